#include <knee_contact/base/input.h>
#include <knee_contact/base/interruption.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/mesh_readers.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <tuple>

namespace knee_contact
{
  template <int dim>
  void
  MeshInput<dim>::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh");
    input::add_selection(
      prm,
      "Source",
      source,
      {{"rectangles", Source::rectangles}, {"file", Source::file}},
      "Where the mesh comes from: 'file' (Gmsh .msh or .geo, Abaqus .inp, "
      "legacy VTK .vtk) or 'rectangles' (built in, for simple scenes and "
      "tests).");
    prm.add_parameter(
      "File",
      entries.file,
      "Mesh file, relative to the scene file, read by its extension: .msh "
      "(Gmsh 2.2 or 4.1, ASCII or binary) or .geo (meshed by the gmsh "
      "program): in 2D "
      "physical surfaces become material ids, physical curves boundary ids; "
      "a mesh with tetrahedra or hexahedra is solved in 3D, with physical "
      "volumes as material ids and physical surfaces as boundary ids. 2D "
      "only: .inp (Abaqus input deck): see Abaqus element sets and Abaqus "
      "boundary sets; .vtk (legacy VTK, layouts 4.2 and 5.1, ASCII or "
      "binary) and .vtu (VTK XML), unstructured grids: the cell field "
      "MaterialID (or gmsh:physical, CellEntityIds, medit:ref) gives "
      "material ids, and of line cells boundary ids; .ucd (AVS UCD). 2D cells "
      "are triangles, "
      "quadrilaterals or both.",
      Patterns::FileName());
    input::add_selection(
      prm,
      "Triangles",
      split_triangles,
      {{"P1", false}, {"quadrilaterals", true}},
      "How a mesh of triangles is solved: 'P1' (the seed's linear "
      "triangles) or 'quadrilaterals' (each triangle split at its centroid "
      "into three quadrilaterals, solved with Q1). A mesh of triangles and "
      "quadrilaterals is always split (every triangle into three, every "
      "quadrilateral into four), and so is a triangle mesh refined "
      "adaptively: deal.II 9.4 cannot do these with triangles (see the "
      "README).");
    prm.add_parameter(
      "Abaqus element sets",
      entries.abaqus_element_sets,
      "For an .inp file: 'NAME: material id; ...', the element sets "
      "(*Elset, or ELSET= of *Element) that make the materials. Empty: the "
      "element sets of the *Solid Section lines get material ids 1, 2, ... "
      "in file order.",
      input::named_list_pattern(Patterns::Integer(0, 254)));
    prm.add_parameter(
      "Abaqus boundary sets",
      entries.abaqus_boundary_sets,
      "For an .inp file: 'NAME: boundary id; ...', surfaces (*Surface, "
      "element faces S1-S4) or node sets (*Nset: the boundary edges whose "
      "two nodes are in the set) that the boundary conditions and contact "
      "interfaces name by id.",
      input::named_list_pattern(Patterns::Integer(0, 254)));
    prm.add_parameter(
      "Gmsh arguments",
      entries.gmsh_arguments,
      "Extra arguments for the gmsh program when File is a .geo, e.g. "
      "'-setnumber lc 0.002' or '-clscale 0.5': words, never a command line; "
      "only -setnumber NAME NUMBER, -clscale, -clmin, -clmax, -clcurv and "
      "-smooth NUMBER are accepted.");
    prm.add_parameter("Gmsh time limit",
                      gmsh_time_limit,
                      "Seconds gmsh may take to mesh a .geo before it is "
                      "stopped and the run refused [s].",
                      Patterns::Double(1));
    prm.add_parameter(
      "Gmsh memory limit",
      gmsh_memory_limit,
      "Memory gmsh may take (its address space) to mesh a .geo before it "
      "fails and the run is refused [MB]; 0: a quarter of the memory "
      "available on the machine (the lesser of MemAvailable and the cgroup's "
      "limit; at least 256 MB), which leaves the rest to the solve of the "
      "mesh.",
      Patterns::Double(0));
    // x0, y0, x1, y1 [m], n_x, n_y, material id, group, and the boundary ids
    // of the left, right, bottom and top sides.
    const Patterns::Integer id(0, 254), count(1, 99999);
    prm.add_parameter(
      "Rectangles",
      entries.rectangles,
      "For Source = rectangles: rectangles separated by ';', each 'x0, y0, "
      "x1, y1, n_x, n_y, material id, group, left id, right id, bottom id, "
      "top id' (lengths in m). Rectangles of the same group share vertices "
      "where they meet (bonded); different groups never do (contact).",
      Patterns::List(Patterns::Tuple(",",
                                     Patterns::Double(),
                                     Patterns::Double(),
                                     Patterns::Double(),
                                     Patterns::Double(),
                                     count,
                                     count,
                                     id,
                                     Patterns::Integer(0, 99999),
                                     id,
                                     id,
                                     id,
                                     id),
                     0,
                     Patterns::List::max_int_value,
                     ";"));
    input::add_selection(
      prm,
      "Rectangle cells",
      rectangle_cells,
      {{"quadrilaterals", RectangleCells::quadrilaterals},
       {"triangles", RectangleCells::triangles},
       {"mixed", RectangleCells::mixed}},
      "For Source = rectangles: the cells of each grid cell: one "
      "quadrilateral, two triangles (cut from lower left to upper right), or "
      "mixed (a checkerboard of both).");
    prm.add_parameter("Rotation angle",
                      rotation_degrees,
                      "Rotate the whole mesh about the origin by this angle "
                      "[degrees, counter-clockwise].",
                      Patterns::Double());
    prm.add_parameter("Global refinements",
                      n_refinements,
                      "Refine every cell this many times after reading.",
                      Patterns::Integer(0, 12));
    prm.add_parameter(
      "Circular boundaries",
      entries.circular_boundaries,
      "Boundary ids that are circular arcs, so refinement places new "
      "vertices on the circle: 'id: x_c, y_c; ...' with the centre (x_c, "
      "y_c) [m]; in 3D spheres, 'id: x_c, y_c, z_c; ...'.",
      Patterns::List(
        Patterns::Tuple(":", id, Patterns::List(Patterns::Double(), 2, 3, ",")),
        0,
        Patterns::List::max_int_value,
        ";"));
    prm.leave_subsection();
  }



  template <int dim>
  void
  MeshInput<dim>::check_parameters(const std::string &scene_file)
  {
    file           = input::resolve_path(entries.file, scene_file);
    gmsh_arguments = gmsh_input::arguments(entries.gmsh_arguments);
    const auto read_sets =
      [](const std::vector<std::pair<std::string, unsigned int>> &entry,
         const std::string                                       &parameter,
         std::map<std::string, unsigned int>                     &sets) {
        for (const auto &[set, id] : entry)
          {
            AssertThrow(!set.empty(),
                        ExcMessage(parameter + ": a set without a name"));
            AssertThrow(sets.emplace(set, id).second,
                        ExcMessage(parameter + ": set '" + set +
                                   "' is named twice"));
          }
      };
    read_sets(entries.abaqus_element_sets,
              "Mesh/Abaqus element sets",
              abaqus_element_sets);
    read_sets(entries.abaqus_boundary_sets,
              "Mesh/Abaqus boundary sets",
              abaqus_boundary_sets);

    if (source == Source::file)
      {
        AssertThrow(!entries.file.empty(),
                    ExcMessage("Mesh/File: no file given for Source = file"));
        AssertThrow(std::ifstream(file).good(),
                    ExcMessage("Mesh/File: cannot open '" + file + "'"));
        // A folder opens as a stream on Linux but has no size or lines.
        AssertThrow(std::filesystem::is_regular_file(file),
                    ExcMessage("Mesh/File: '" + file +
                               "' is not a file (a folder?)"));
      }
    else
      for (const auto &entry : entries.rectangles)
        {
          Rectangle r;
          r.lower = Point<2>(std::get<0>(entry), std::get<1>(entry));
          r.upper = Point<2>(std::get<2>(entry), std::get<3>(entry));
          const std::string rectangle = "Mesh/Rectangles: a rectangle from (" +
                                        std::to_string(r.lower[0]) + ", " +
                                        std::to_string(r.lower[1]) + ") to (" +
                                        std::to_string(r.upper[0]) + ", " +
                                        std::to_string(r.upper[1]) + ")";
          AssertThrow(r.upper[0] > r.lower[0] && r.upper[1] > r.lower[1],
                      ExcMessage(rectangle + " needs x1 > x0 and y1 > y0"));
          AssertThrow(std::isfinite(r.upper[0] - r.lower[0]) &&
                        std::isfinite(r.upper[1] - r.lower[1]),
                      ExcMessage(rectangle + " is not finite"));
          r.n_x          = std::get<4>(entry);
          r.n_y          = std::get<5>(entry);
          r.material_id  = static_cast<types::material_id>(std::get<6>(entry));
          r.group        = std::get<7>(entry);
          r.boundary_ids = {{std::get<8>(entry),
                             std::get<9>(entry),
                             std::get<10>(entry),
                             std::get<11>(entry)}};
          rectangles.push_back(r);
        }
    // make_rectangles_2d() finds shared vertices by their coordinates
    // rounded to 1e-6 of the smallest cell size in a long: no coordinate
    // may lie 1e12 of those cell sizes from the origin (-1e308 passes
    // Patterns::Double but overflows the rounding).
    double smallest_cell = std::numeric_limits<double>::max(), extent = 0;
    for (const Rectangle &r : rectangles)
      {
        smallest_cell = std::min({smallest_cell,
                                  (r.upper[0] - r.lower[0]) / r.n_x,
                                  (r.upper[1] - r.lower[1]) / r.n_y});
        for (unsigned int d = 0; d < 2; ++d)
          extent =
            std::max({extent, std::abs(r.lower[d]), std::abs(r.upper[d])});
      }
    if (!(extent < 1e12 * smallest_cell))
      {
        std::ostringstream message;
        message << "Mesh/Rectangles: coordinates up to " << extent
                << " m with cells of " << smallest_cell
                << " m: the cells must be larger than 1e-12 of the largest "
                   "coordinate";
        AssertThrow(false, ExcMessage(message.str()));
      }

    for (const auto &[id, centre] : entries.circular_boundaries)
      {
        AssertThrow(centre.size() == dim,
                    ExcMessage("Mesh/Circular boundaries: the centre of "
                               "boundary id " +
                               std::to_string(id) + " needs " +
                               (dim == 2 ? "x, y (the mesh is 2D)"
                                         : "x, y, z (the mesh is 3D)")));
        Point<dim> c;
        for (unsigned int d = 0; d < dim; ++d)
          c[d] = centre[d];
        circular_boundaries[static_cast<types::boundary_id>(id)] = c;
      }
  }



  template <int dim>
  void
  MeshInput<dim>::create(Triangulation<dim> &triangulation,
                         const int           level,
                         const bool          distributed) const
  {
    triangulation.clear();
    // A level below 0 (the coarse start): a .geo meshed by gmsh at 2^-level
    // times the size, other meshes -level fewer Global refinements. Above 0
    // (a uniform sequence's cycle made anew): level more refinements, or a
    // .geo of tetrahedra meshed at 2^-level times the size (remeshes()).
    const bool geo = from_geo();
    if (source == Source::file)
      read_file(triangulation, geo ? level : 0);
    else
      make_rectangles(triangulation);
    // Tetrahedra of a .geo are refined by gmsh (see remeshes()): Global
    // refinements are levels of its mesh size then.
    unsigned int n_refine = n_refinements;
    if (remeshes(triangulation))
      {
        if (n_refinements > 0)
          {
            triangulation.clear();
            read_file(triangulation, level + int(n_refinements));
          }
        n_refine = 0;
      }
    else if (level > 0)
      {
        // The scene's mesh refined level more times; a .geo of other cells
        // than tetrahedra is read again at its own size.
        if (geo)
          {
            triangulation.clear();
            read_file(triangulation, 0);
          }
        n_refine = n_refinements + level;
      }
    else if (level < 0 && !geo)
      {
        // coarser_levels() was asked first.
        AssertThrow(int(n_refinements) + level >= 0, ExcInternalError());
        n_refine = n_refinements + level;
      }

    AssertThrow(triangulation.n_active_cells() > 0,
                ExcMessage("Mesh: the mesh has no cells"));
    check_cells(triangulation);

    if (rotation_degrees != 0)
      {
        if constexpr (dim == 2)
          GridTools::rotate(rotation_degrees * numbers::PI / 180,
                            triangulation);
        else
          // About the z axis, as in 2D.
          GridTools::rotate(Tensor<1, 3>({0., 0., 1.}),
                            rotation_degrees * numbers::PI / 180,
                            triangulation);
      }
    attach_manifolds(triangulation);

    // A 3D mesh of tetrahedra has about 5.5 cells per vertex where one of
    // hexahedra has one: its run costs what a hexahedral mesh of twice its
    // vertices does (measured peaks, prm/hertz_sphere_3d.geo: 0.52, 1.15 and
    // 3.44 GB at 3.6e4, 8.7e4 and 2.3e5 tetrahedra; the estimate 0.49, 1.12
    // and 3.9 GB; by cells it was 4.6 times too much and refused a mesh of
    // 6.1e5 tetrahedra that fits).
    const bool tetrahedra =
      dim == 3 && triangulation.all_reference_cells_are_simplex();
    check_run_fits(dim,
                   (tetrahedra ? 2. * triangulation.n_vertices()
                               : double(triangulation.n_active_cells())) *
                     std::pow(double(1u << dim), n_refine),
                   (n_refine > 0 ? "Mesh/Global refinements: " +
                                     std::to_string(n_refine) + " refinements"
                                 : std::string("Mesh: the scene's mesh")) +
                     (tetrahedra ? " (tetrahedra: as hexahedra of twice its "
                                   "vertices)"
                                 : ""),
                   tetrahedra,
                   distributed);
    triangulation.refine_global(n_refine);
    if (n_refine > 0)
      check_cells(triangulation);
  }



  template <int dim>
  void
  MeshInput<dim>::check_coarser_levels(const unsigned int levels) const
  {
    AssertThrow(from_geo() || levels <= n_refinements,
                ExcMessage(
                  "Contact/Coarse start levels: " + std::to_string(levels) +
                  (levels == 1 ? " coarser level needs"
                               : " coarser levels need") +
                  " a .geo (gmsh meshes it coarser) or at least as "
                  "many Mesh/Global refinements (this scene has " +
                  std::to_string(n_refinements) + ")"));
  }



  template <int dim>
  bool
  MeshInput<dim>::from_geo() const
  {
    return source == Source::file &&
           std::filesystem::path(file).extension() == ".geo";
  }



  template <int dim>
  bool
  MeshInput<dim>::remeshes(const Triangulation<dim> &triangulation) const
  {
    // deal.II 9.4 cuts every tetrahedron's inner octahedron along the same
    // diagonal, so the cells degrade with each level (deal.II issue 16688,
    // fixed in 9.6): measured on the unit cube, the P1 L2 rate fell from
    // 2.2 to 1.37 over three levels and the energy rate to 0.77. gmsh
    // meshing the .geo anew at half the size keeps the quality.
    return dim == 3 && from_geo() && triangulation.n_active_cells() > 0 &&
           triangulation.all_reference_cells_are_simplex();
  }



  template <int dim>
  void
  MeshInput<dim>::attach_manifolds(Triangulation<dim> &triangulation) const
  {
    // deal.II 9.4's SphericalManifold::normal_vector() reads a fourth
    // vertex of every face: on triangles it reads past the face (a
    // segmentation fault in the no-normal-flux constraints, seen).
    AssertThrow(dim == 2 || circular_boundaries.empty() ||
                  !triangulation.all_reference_cells_are_simplex(),
                ExcMessage("Mesh/Circular boundaries: not for tetrahedra "
                           "(deal.II 9.4's spherical manifold fails on "
                           "triangular faces); from a .geo, gmsh meshes "
                           "every refinement level on the true surface "
                           "anyway"));
    types::manifold_id manifold = 1;
    for (const auto &[id, centre] : circular_boundaries)
      {
        Point<dim> c = centre;
        if (rotation_degrees != 0)
          {
            const double a = rotation_degrees * numbers::PI / 180;
            c[0]           = std::cos(a) * centre[0] - std::sin(a) * centre[1];
            c[1]           = std::sin(a) * centre[0] + std::cos(a) * centre[1];
          }
        bool found = false;
        for (const auto &face : triangulation.active_face_iterators())
          if (face->at_boundary() && face->boundary_id() == id)
            {
              // PolarManifold and SphericalManifold put new vertices at the
              // radius of the face's vertices: all must lie on one circle
              // (sphere) about the centre.
              const double r0 = face->vertex(0).distance(c),
                           r1 = face->vertex(1).distance(c);
              if constexpr (dim == 2)
                {
                  AssertThrow(
                    r0 > 0 && std::abs(r0 - r1) <= 1e-6 * std::max(r0, r1) &&
                      face->vertex(0).distance(face->vertex(1)) <
                        std::max(r0, r1),
                    ExcMessage(
                      "Mesh/Circular boundaries: the edge of boundary "
                      "id " +
                      std::to_string(id) + " from (" +
                      std::to_string(face->vertex(0)[0]) + ", " +
                      std::to_string(face->vertex(0)[1]) + ") to (" +
                      std::to_string(face->vertex(1)[0]) + ", " +
                      std::to_string(face->vertex(1)[1]) +
                      ") is not an arc about the given centre (radii " +
                      std::to_string(r0) + " and " + std::to_string(r1) + ")"));
                }
              else
                {
                  double r_min = r0, r_max = r0;
                  for (const unsigned int v : face->vertex_indices())
                    {
                      r_min = std::min(r_min, face->vertex(v).distance(c));
                      r_max = std::max(r_max, face->vertex(v).distance(c));
                    }
                  AssertThrow(
                    r_min > 0 && r_max - r_min <= 1e-6 * r_max &&
                      face->diameter() < r_max,
                    ExcMessage(
                      "Mesh/Circular boundaries: the face of boundary id " +
                      std::to_string(id) + " at (" +
                      std::to_string(face->center()[0]) + ", " +
                      std::to_string(face->center()[1]) + ", " +
                      std::to_string(face->center()[2]) +
                      ") is not on a sphere about the given centre (radii " +
                      std::to_string(r_min) + " to " + std::to_string(r_max) +
                      ")"));
                }
              // In 3D the face's edges follow the sphere too.
              if constexpr (dim == 2)
                face->set_manifold_id(manifold);
              else
                face->set_all_manifold_ids(manifold);
              found = true;
            }
        AssertThrow(found,
                    ExcMessage("Mesh/Circular boundaries: the mesh has no "
                               "boundary id " +
                               std::to_string(id)));
        if constexpr (dim == 2)
          triangulation.set_manifold(manifold, PolarManifold<2>(c));
        else
          triangulation.set_manifold(manifold, SphericalManifold<3>(c));
        ++manifold;
      }
  }



  // The members that read files and make rectangles are in mesh_files.cc.
  double
  estimated_run_bytes(const unsigned int dim,
                      const double       n_cells,
                      const bool         tetrahedra)
  {
    // About 8 kB per cell in 2D for matrix, factorisation and vectors
    // (measured: 1.8 GB for 236 544 cells with contact); in 3D the factor
    // fills in more: measured 1.3 GB peak for 32 768 hexahedra (1.1e5
    // DoFs), 35 kB per cell, and 21 kB at 4 096 (about cells^(1/4));
    // estimated with cells^(1/3) above 3.3e4 to stay on the safe side.
    if (dim == 2)
      return 8e3 * n_cells;
    const double direct =
      3.5e4 * std::max(1., std::cbrt(n_cells / 3.3e4)) * n_cells;
    // Where a factor does not fit, the iterative path (CG with AMG) solves
    // in memory linear in the dofs: 40 bytes per matrix entry (the matrix,
    // Trilinos' condensed copy and the hierarchy) and 2.5 kB per dof (mesh,
    // DoF handler, vectors, error bars, output; measured on the 3D knee's
    // tetrahedra, 45 entries a row: 4.1 kB per dof at 1.0e6 dofs, 3.9 at
    // 1.7e6), beside 50 MB for the results (the libraries are loaded and
    // counted as used already). Hexahedra have about one dof triple per
    // cell and 81 entries a row; tetrahedra (as hexahedra of twice their
    // vertices) 1.5 dofs per such cell and 45 entries. (The former 12 kB
    // per such cell, 8 kB per tetrahedral dof, refused the knee at 4.2e6
    // dofs: 33 GB.) On N ranks (each holds the mesh whole) each rank holds
    // C's pattern whole (4 bytes an entry) and its share of the rest: C is
    // assembled only as the path's rows there.
    const double dofs      = (tetrahedra ? 1.5 : 3.) * n_cells;
    const double entries   = tetrahedra ? 45 : 81;
    const double per_entry = 4. + 36. / parallel::n_ranks();
    return std::min(direct, 5e7 + dofs * (2.5e3 + per_entry * entries));
  }



  void
  estimated_distributed_bytes(const double n_cells,
                              const bool   tetrahedra,
                              double      &first,
                              double      &other)
  {
    // Measured on the 3D knee's tetrahedra at 1.0e6 dofs (doc/parallel.md,
    // 2026-12-02): one process 4.0 GB (the estimate above 4.35); on N
    // ranks each holds 491 MB (the program's 176 and 0.3 kB a dof: the
    // vectors, the contact rows, whole) and 3.5 kB a dof divided (the mesh
    // part, DoFs, C's rows, the hierarchy); rank 0 holds the whole mesh
    // and its part first: 1.64 GB on two ranks, 1.22 on four. Here 0.4 kB
    // a dof whole, the rest of the one-process estimate divided, and 1.5
    // kB a dof for rank 0's mesh phase.
    const double dofs    = (tetrahedra ? 1.5 : 3.) * n_cells;
    const double entries = tetrahedra ? 45 : 81;
    const double ranks   = parallel::n_ranks();
    other = 5e7 + dofs * (400. + (2.1e3 + 40. * entries) / ranks);
    first = std::max(other, 5e7 + 1.5e3 * dofs);
  }



  void
  check_run_fits(const unsigned int dim,
                 const double       n_cells,
                 const std::string &what,
                 const bool         tetrahedra,
                 const bool         distributed)
  {
    // (A 2D run's estimate is that of its whole mesh on every rank.)
    const bool  divided = distributed && dim == 3 && parallel::n_ranks() > 1;
    std::string limit;
    double      available = memory::available(limit, !divided);
    double      needed    = estimated_run_bytes(dim, n_cells, tetrahedra);
    std::string whose;
    if (divided)
      {
        // The machine's share of a rank (memory::available()) against
        // what its ranks hold on average: rank 0 more, the others their
        // share; rank 0's own against an address-space limit.
        double first = 0, other = 0;
        estimated_distributed_bytes(n_cells, tetrahedra, first, other);
        const double here = parallel::ranks_on_this_machine();
        needed            = (first + (here - 1) * other) / here;
        whose             = " a rank on the distributed mesh";
        if (memory::address_space_limited())
          {
            const double room =
              memory::address_space_limit() - memory::process_virtual();
            if (room - first < available - needed)
              {
                available = room;
                needed    = first;
                whose     = " on rank 0, which makes the distributed mesh";
                limit     = "the address-space limit (ulimit -v)";
              }
          }
      }
    const auto gigabytes = [](const double bytes) {
      std::ostringstream out;
      out << std::setprecision(3) << bytes / 1e9 << " GB";
      return out.str();
    };
    std::ostringstream cells;
    cells << std::setprecision(3) << n_cells;
    AssertThrow(needed < available,
                ExcMessage(what + ": about " + cells.str() +
                           " cells need about " + gigabytes(needed) + whose +
                           "; " + gigabytes(available) + " are available (" +
                           limit + ")"));
  }



  template class MeshInput<2>;
  template class MeshInput<3>;
} // namespace knee_contact
