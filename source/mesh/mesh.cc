#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/core/input.h>
#include <knee_contact/core/interruption.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/mesh_readers.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>

#include <iomanip>
#include <memory>
#include <sstream>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>
#include <tuple>

namespace knee_contact
{
  template <int dim>
  void
  MeshInput<dim>::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh");
    prm.declare_entry("Source",
                      "rectangles",
                      Patterns::Selection("rectangles|file"),
                      "Where the mesh comes from: 'file' (Gmsh .msh or .geo, "
                      "Abaqus .inp, legacy VTK .vtk) or 'rectangles' (built "
                      "in, for simple scenes and tests).");
    prm.declare_entry("File",
                      "",
                      Patterns::Anything(),
                      "Mesh file, relative to the scene file, read by its "
                      "extension: .msh (Gmsh 2.2 or 4.1 ASCII) or .geo "
                      "(meshed by the gmsh program): in 2D physical surfaces "
                      "become material ids, physical curves boundary ids; "
                      "a mesh with tetrahedra or hexahedra is solved in 3D, "
                      "with physical volumes as material ids and physical "
                      "surfaces as boundary ids. 2D only: .inp (Abaqus input "
                      "deck): see Abaqus element sets and Abaqus boundary "
                      "sets; .vtk (legacy ASCII VTK) and .vtu (VTK XML), "
                      "unstructured grids: the cell field MaterialID gives "
                      "material ids, and of line cells boundary ids; .ucd "
                      "(AVS UCD). 2D cells are triangles, quadrilaterals or "
                      "both.");
    prm.declare_entry("Triangles",
                      "P1",
                      Patterns::Selection("P1|quadrilaterals"),
                      "How a mesh of triangles is solved: 'P1' (the seed's "
                      "linear triangles) or 'quadrilaterals' (each triangle "
                      "split at its centroid into three quadrilaterals, "
                      "solved with Q1). A mesh of triangles and "
                      "quadrilaterals is always split (every triangle into "
                      "three, every quadrilateral into four), and so is a "
                      "triangle mesh refined adaptively: deal.II 9.4 cannot "
                      "do these with triangles (see the README).");
    prm.declare_entry("Abaqus element sets",
                      "",
                      Patterns::Anything(),
                      "For an .inp file: 'NAME: material id; ...', the "
                      "element sets (*Elset, or ELSET= of *Element) that "
                      "make the materials. Empty: the element sets of the "
                      "*Solid Section lines get material ids 1, 2, ... in "
                      "file order.");
    prm.declare_entry("Abaqus boundary sets",
                      "",
                      Patterns::Anything(),
                      "For an .inp file: 'NAME: boundary id; ...', surfaces "
                      "(*Surface, element faces S1-S4) or node sets (*Nset: "
                      "the boundary edges whose two nodes are in the set) "
                      "that the boundary conditions and contact interfaces "
                      "name by id.");
    prm.declare_entry("Gmsh arguments",
                      "",
                      Patterns::Anything(),
                      "Extra arguments for the gmsh program when File is a "
                      ".geo, e.g. '-setnumber lc 0.002' or '-clscale 0.5': "
                      "words, never a command line; only -setnumber NAME "
                      "NUMBER, -clscale, -clmin, -clmax, -clcurv and -smooth "
                      "NUMBER are accepted.");
    prm.declare_entry("Gmsh time limit",
                      "300",
                      Patterns::Double(1),
                      "Seconds gmsh may take to mesh a .geo before it is "
                      "stopped and the run refused [s].");
    prm.declare_entry(
      "Rectangles",
      "0, 0, 1, 1, 1, 1, 1, 0, 1, 2, 3, 4",
      Patterns::Anything(),
      "For Source = rectangles: rectangles separated by ';', each 'x0, y0, "
      "x1, y1, n_x, n_y, material id, group, left id, right id, bottom id, "
      "top id' (lengths in m). Rectangles of the same group share vertices "
      "where they meet (bonded); different groups never do (contact).");
    prm.declare_entry("Rectangle cells",
                      "quadrilaterals",
                      Patterns::Selection("quadrilaterals|triangles|mixed"),
                      "For Source = rectangles: the cells of each grid "
                      "cell: one quadrilateral, two triangles (cut from "
                      "lower left to upper right), or mixed (a checkerboard "
                      "of both).");
    prm.declare_entry("Rotation angle",
                      "0",
                      Patterns::Double(),
                      "Rotate the whole mesh about the origin by this angle "
                      "[degrees, counter-clockwise].");
    prm.declare_entry("Global refinements",
                      "0",
                      Patterns::Integer(0, 12),
                      "Refine every cell this many times after reading.");
    prm.declare_entry("Circular boundaries",
                      "",
                      Patterns::Anything(),
                      "Boundary ids that are circular arcs, so refinement "
                      "places new vertices on the circle: 'id: x_c, y_c; ...' "
                      "with the centre (x_c, y_c) [m]; in 3D spheres, "
                      "'id: x_c, y_c, z_c; ...'.");
    prm.leave_subsection();
  }



  template <int dim>
  void
  MeshInput<dim>::parse_parameters(ParameterHandler  &prm,
                                   const std::string &scene_file)
  {
    prm.enter_subsection("Mesh");
    source = prm.get("Source") == "file" ? Source::file : Source::rectangles;
    file   = input::resolve_path(prm.get("File"), scene_file);
    gmsh_arguments  = gmsh_input::arguments(prm.get("Gmsh arguments"));
    gmsh_time_limit = prm.get_double("Gmsh time limit");
    split_triangles = prm.get("Triangles") == "quadrilaterals";
    rectangle_cells =
      prm.get("Rectangle cells") == "triangles" ? RectangleCells::triangles
      : prm.get("Rectangle cells") == "mixed"   ? RectangleCells::mixed
                                              : RectangleCells::quadrilaterals;
    const auto read_sets = [](const std::string                   &text,
                              const std::string                   &parameter,
                              std::map<std::string, unsigned int> &sets) {
      for (const auto &[set, id_text] :
           input::split_named(text, parameter, "NAME: id"))
        {
          const double id = input::to_double(id_text, parameter);
          AssertThrow(id >= 0 && id < 255 && id == std::floor(id),
                      ExcMessage(parameter + ": '" + id_text + "' for set '" +
                                 set + "' is not an id in 0..254"));
          AssertThrow(sets.emplace(set, static_cast<unsigned int>(id)).second,
                      ExcMessage(parameter + ": set '" + set +
                                 "' is named twice"));
        }
    };
    read_sets(prm.get("Abaqus element sets"),
              "Mesh/Abaqus element sets",
              abaqus_element_sets);
    read_sets(prm.get("Abaqus boundary sets"),
              "Mesh/Abaqus boundary sets",
              abaqus_boundary_sets);
    rotation_degrees = prm.get_double("Rotation angle");
    n_refinements    = prm.get_integer("Global refinements");
    AssertThrow(std::isfinite(rotation_degrees),
                ExcMessage("Mesh/Rotation angle is not a finite number"));

    if (source == Source::file)
      {
        AssertThrow(!prm.get("File").empty(),
                    ExcMessage("Mesh/File: no file given for Source = file"));
        AssertThrow(std::ifstream(file).good(),
                    ExcMessage("Mesh/File: cannot open '" + file + "'"));
        // A folder opens as a stream on Linux but has no size or lines.
        AssertThrow(std::filesystem::is_regular_file(file),
                    ExcMessage("Mesh/File: '" + file +
                               "' is not a file (a folder?)"));
      }
    else
      for (const auto &text : input::split(prm.get("Rectangles"), ';'))
        {
          const auto v = input::split(text, ',');
          AssertThrow(v.size() == 12,
                      ExcMessage("Mesh/Rectangles: '" + text +
                                 "' does not have 12 numbers"));
          std::array<double, 12> n;
          for (unsigned int i = 0; i < 12; ++i)
            n[i] = input::to_double(v[i], "Mesh/Rectangles");
          for (unsigned int i = 4; i < 12; ++i)
            AssertThrow(n[i] >= 0 && n[i] == std::floor(n[i]) &&
                          n[i] < (i < 6 ? 1e5 : 255),
                        ExcMessage("Mesh/Rectangles: '" + v[i] + "' in '" +
                                   text + "' must be a non-negative integer"));
          Rectangle r;
          r.lower = Point<2>(n[0], n[1]);
          r.upper = Point<2>(n[2], n[3]);
          AssertThrow(r.upper[0] > r.lower[0] && r.upper[1] > r.lower[1],
                      ExcMessage("Mesh/Rectangles: '" + text +
                                 "' needs x1 > x0 and y1 > y0"));
          r.n_x         = static_cast<unsigned int>(n[4]);
          r.n_y         = static_cast<unsigned int>(n[5]);
          r.material_id = static_cast<types::material_id>(n[6]);
          r.group       = static_cast<unsigned int>(n[7]);
          AssertThrow(r.n_x > 0 && r.n_y > 0,
                      ExcMessage("Mesh/Rectangles: '" + text +
                                 "' needs n_x, n_y >= 1"));
          for (unsigned int i = 0; i < 4; ++i)
            r.boundary_ids[i] = static_cast<types::boundary_id>(n[8 + i]);
          rectangles.push_back(r);
        }

    const std::string circles = "Mesh/Circular boundaries";
    for (const auto &[id_text, centre] : input::split_named(
           prm.get("Circular boundaries"), circles, "id: x_c, y_c"))
      {
        const double id = input::to_double(id_text, circles);
        AssertThrow(id >= 0 && id < 255 && id == std::floor(id),
                    ExcMessage(circles + ": '" + id_text +
                               "' is not a boundary id"));
        circular_boundaries[static_cast<types::boundary_id>(id)] =
          input::to_point<dim>(centre, circles);
      }
    prm.leave_subsection();
  }



  template <int dim>
  void
  MeshInput<dim>::create(Triangulation<dim> &triangulation,
                         const unsigned int  level) const
  {
    triangulation.clear();
    if (source == Source::file)
      read_file(triangulation, level);
    else
      make_rectangles(triangulation);
    // Tetrahedra of a .geo are refined by gmsh (see remeshes()): Global
    // refinements are levels of its mesh size then.
    unsigned int n_refine = n_refinements;
    if (remeshes(triangulation))
      {
        if (level == 0 && n_refinements > 0)
          {
            triangulation.clear();
            read_file(triangulation, n_refinements);
          }
        n_refine = 0;
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

    // Refuse early a mesh the machine cannot hold: about 8 kB per cell in
    // 2D for matrix, factorisation and vectors (measured: 1.8 GB for
    // 236 544 cells with contact); in 3D the factor fills in more:
    // measured 35 kB per hexahedron at 3.3e4 cells, growing with the mesh.
    const double n_cells = triangulation.n_active_cells() *
                           std::pow(double(1u << dim), n_refine);
    const double needed =
      (dim == 2 ? 8e3 : 3.5e4 * std::max(1., std::cbrt(n_cells / 3.3e4))) *
      n_cells;
    double       available = 0;
    {
      std::ifstream meminfo("/proc/meminfo");
      std::string   key;
      double        kb = 0;
      while (meminfo >> key >> kb)
        {
          if (key == "MemAvailable:")
            available = kb * 1024;
          meminfo.ignore(256, '\n');
        }
    }
    AssertThrow(available == 0 || needed < available,
                ExcMessage(
                  "Mesh/Global refinements: " + std::to_string(n_refine) +
                  " refinements give about " +
                  std::to_string(static_cast<long long>(n_cells)) +
                  " cells, needing about " +
                  std::to_string(static_cast<long long>(needed / 1e9)) +
                  " GB; this machine has " +
                  std::to_string(available / 1e9).substr(0, 5) +
                  " GB available"));
    triangulation.refine_global(n_refine);
    if (n_refine > 0)
      check_cells(triangulation);
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
    return dim == 3 && source == Source::file &&
           std::filesystem::path(file).extension() == ".geo" &&
           triangulation.n_active_cells() > 0 &&
           triangulation.all_reference_cells_are_simplex();
  }



  template <int dim>
  void
  MeshInput<dim>::attach_manifolds(Triangulation<dim> &triangulation) const
  {
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
                  ExcMessage("Mesh/Circular boundaries: the edge of boundary "
                             "id " +
                             std::to_string(id) + " from (" +
                             std::to_string(face->vertex(0)[0]) + ", " +
                             std::to_string(face->vertex(0)[1]) + ") to (" +
                             std::to_string(face->vertex(1)[0]) + ", " +
                             std::to_string(face->vertex(1)[1]) +
                             ") is not an arc about the given centre (radii " +
                             std::to_string(r0) + " and " +
                             std::to_string(r1) + ")"));
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



  template <int dim>
  void
  check_cells(const Triangulation<dim> &triangulation)
  {
    // The Jacobian of a bilinear quadrilateral is positive everywhere iff
    // the cross products of the edges at all four corners are (deal.II's
    // vertex order 0 1 3 2 runs counter-clockwise); a triangle's at any.
    // A trilinear hexahedron needs the triple product of its three edges
    // positive at all eight corners (necessary; sufficient for the
    // parallelepipeds and mildly distorted cells meshers make), a
    // tetrahedron at one. Checked on every mesh the program solves on:
    // refinement on a circle that does not fit the vertices can fold cells.
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int n  = cell->n_vertices();
        bool               ok = true;
        if constexpr (dim == 2)
          {
            // A triangle's vertices 0 1 2 run counter-clockwise too.
            const std::array<unsigned int, 4> ring =
              n == 3 ? std::array<unsigned int, 4>{{0, 1, 2}}
                     : std::array<unsigned int, 4>{{0, 1, 3, 2}};
            for (unsigned int k = 0; k < n; ++k)
              {
                const Tensor<1, 2> a =
                  cell->vertex(ring[(k + 1) % n]) - cell->vertex(ring[k]);
                const Tensor<1, 2> b =
                  cell->vertex(ring[(k + n - 1) % n]) - cell->vertex(ring[k]);
                ok &= a[0] * b[1] - a[1] * b[0] > 1e-12 * a.norm() * b.norm();
              }
          }
        else
          // Corner v = i + 2j + 4k of a hexahedron has its neighbours along
          // the three directions at v ^ 1, v ^ 2, v ^ 4, a right-handed
          // triple if i + j + k is even; a tetrahedron's corner 0 has 1 2 3.
          for (unsigned int v = 0; v < (n == 4 ? 1u : 8u); ++v)
            {
              const std::array<unsigned int, 3> next =
                n == 4 ? std::array<unsigned int, 3>{{1, 2, 3}}
                       : std::array<unsigned int, 3>{{v ^ 1u, v ^ 2u, v ^ 4u}};
              const Tensor<1, dim> a = cell->vertex(next[0]) - cell->vertex(v),
                                   b = cell->vertex(next[1]) - cell->vertex(v),
                                   c = cell->vertex(next[2]) - cell->vertex(v);
              const double sign =
                (((v & 1) + ((v >> 1) & 1) + ((v >> 2) & 1)) % 2 == 0) ? 1. :
                                                                         -1.;
              ok &= sign * (cross_product_3d(a, b) * c) >
                    1e-12 * a.norm() * b.norm() * c.norm();
            }
        if (!ok)
          {
            std::string centre;
            for (unsigned int d = 0; d < dim; ++d)
              centre += (d == 0 ? "" : ", ") + std::to_string(cell->center()[d]);
            AssertThrow(false,
                        ExcMessage("Mesh: cell at (" + centre +
                                   ") is inverted, degenerate or not convex" +
                                   (cell->level() > 0
                                      ? " after refinement (level " +
                                          std::to_string(cell->level()) + ")"
                                      : std::string())));
          }
      }
  }



  namespace
  {
    /**
     * A .msh ready to read: the user's file, or the mesh gmsh made of a .geo
     * in a private temporary folder (removed on Ctrl-C too, and when this
     * goes), checked by check_msh, with the dimension of its cells.
     */
    struct CheckedMsh
    {
      std::string              file;
      std::vector<std::string> arguments;
      std::string              msh;
      std::string              folder;
      unsigned int             dim = 0;

      ~CheckedMsh()
      {
        if (!folder.empty())
          {
            interruption::unregister_folder(folder);
            std::error_code ignored;
            std::filesystem::remove_all(folder, ignored);
          }
      }
    };

    /**
     * The mesh scene_dimension() checked, kept for MeshInput::read_gmsh()
     * so that a .geo is meshed once per run.
     */
    std::unique_ptr<CheckedMsh> kept_msh;

    std::unique_ptr<CheckedMsh>
    checked_msh(const std::string              &file,
                const std::vector<std::string> &arguments,
                const double                    time_limit)
    {
      if (kept_msh && kept_msh->file == file &&
          kept_msh->arguments == arguments)
        return std::move(kept_msh);
      auto result       = std::make_unique<CheckedMsh>();
      result->file      = file;
      result->arguments = arguments;
      result->msh       = file;
      if (std::filesystem::path(file).extension() == ".geo")
        {
          std::string folder =
            (std::filesystem::temp_directory_path() / "knee_contact_XXXXXX")
              .string();
          AssertThrow(mkdtemp(folder.data()) != nullptr,
                      ExcMessage("cannot create a temporary folder for gmsh"));
          interruption::register_folder(folder);
          result->folder = folder;
          result->msh    = folder + "/mesh.msh";
          gmsh_input::mesh(file, result->msh, arguments, time_limit);
        }
      // deal.II's reader trusts its input; check the file first.
      try
        {
          result->dim = gmsh_input::check_msh(result->msh);
        }
      catch (const std::exception &exc)
        {
          // Name the user's .geo, not the temporary file.
          std::string message = exc.what();
          const auto  at      = message.find("'" + result->msh + "'");
          if (result->msh != file && at != std::string::npos)
            message.replace(at,
                            result->msh.size() + 2,
                            "the mesh gmsh made of '" + file + "',");
          AssertThrow(false, ExcMessage(message));
        }
      return result;
    }
  } // namespace



  unsigned int
  scene_dimension(ParameterHandler &prm, const std::string &scene_file)
  {
    prm.enter_subsection("Mesh");
    const bool        from_file = prm.get("Source") == "file";
    const std::string file = input::resolve_path(prm.get("File"), scene_file);
    const auto arguments   = gmsh_input::arguments(prm.get("Gmsh arguments"));
    const double time_limit = prm.get_double("Gmsh time limit");
    prm.leave_subsection();
    const auto extension = std::filesystem::path(file).extension();
    // Anything else is 2D; a missing file is reported by MeshInput.
    if (!from_file || (extension != ".msh" && extension != ".geo") ||
        !std::filesystem::is_regular_file(file) || !std::ifstream(file).good())
      return 2;
    kept_msh = checked_msh(file, arguments, time_limit);
    return kept_msh->dim;
  }



  template <int dim>
  mesh_readers::Description<dim>
  MeshInput<dim>::read_gmsh(const unsigned int level) const
  {
    // Level L: the mesh size times 2^-L (gmsh's -clscale, on top of one the
    // scene gives).
    std::vector<std::string> arguments = gmsh_arguments;
    if (level > 0)
      {
        const double factor = std::pow(0.5, level);
        const auto   it = std::find(arguments.begin(), arguments.end(), "-clscale");
        std::ostringstream scale;
        scale << std::setprecision(17)
              << factor * (it != arguments.end() && it + 1 != arguments.end()
                             ? std::stod(*(it + 1))
                             : 1.);
        if (it != arguments.end() && it + 1 != arguments.end())
          *(it + 1) = scale.str();
        else
          arguments.insert(arguments.end(), {"-clscale", scale.str()});
      }
    auto msh = checked_msh(file, arguments, gmsh_time_limit);
    AssertThrow(msh->dim == dim, ExcInternalError());
    Triangulation<dim> read;
    GridIn<dim>        grid_in;
    grid_in.attach_triangulation(read);
    std::ifstream in(msh->msh);
    try
      {
        grid_in.read_msh(in);
      }
    catch (const std::exception &exc)
      {
        AssertThrow(false,
                    ExcMessage("Mesh/File: cannot read '" + file +
                               "' as a Gmsh mesh (" +
                               input::one_line(exc.what()) + ")"));
      }
    msh.reset();
    mesh_readers::Description<dim> mesh;
    std::tie(mesh.vertices, mesh.cells, mesh.subcells) =
      GridTools::get_coarse_mesh_description(read);
    return mesh;
  }



  template <int dim>
  mesh_readers::Description<2>
  MeshInput<dim>::read_vtk() const
  {
    mesh_readers::check_vtk(file);
    Triangulation<2> read;
    GridIn<2>        grid_in;
    grid_in.attach_triangulation(read);
    std::ifstream in(file);
    try
      {
        grid_in.read_vtk(in);
      }
    catch (const std::exception &exc)
      {
        AssertThrow(false,
                    ExcMessage("Mesh/File: cannot read '" + file +
                               "' as a VTK mesh (" +
                               input::one_line(exc.what()) + ")"));
      }
    mesh_readers::Description<2> mesh;
    std::tie(mesh.vertices, mesh.cells, mesh.subcells) =
      GridTools::get_coarse_mesh_description(read);
    return mesh;
  }



  template <int dim>
  void
  MeshInput<dim>::read_file(Triangulation<dim> &triangulation,
                            const unsigned int  level) const
  {
    const std::string extension = std::filesystem::path(file).extension();
    AssertThrow(extension == ".inp" ||
                  (abaqus_element_sets.empty() && abaqus_boundary_sets.empty()),
                ExcMessage("Mesh/Abaqus element sets and Abaqus boundary sets "
                           "are for .inp files, not '" +
                           file + "'"));
    mesh_readers::Description<dim> mesh;
    if (extension == ".msh" || extension == ".geo")
      mesh = read_gmsh(level);
    else if constexpr (dim == 3)
      {
        // scene_dimension() gives 3 for Gmsh files only.
        AssertThrow(false, ExcInternalError());
      }
    else
      {
        if (extension == ".inp")
          mesh = mesh_readers::read_abaqus(file,
                                           abaqus_element_sets,
                                           abaqus_boundary_sets);
        else if (extension == ".vtk")
          mesh = read_vtk();
        else if (extension == ".vtu")
          mesh = mesh_readers::read_vtu(file);
        else if (extension == ".ucd")
          mesh = mesh_readers::read_ucd(file);
        else
          AssertThrow(false,
                      ExcMessage("Mesh/File: '" + file +
                                 "' has an extension knee_contact does not "
                                 "read (.msh, .geo, .inp, .vtk, .vtu, .ucd)"));
      }

    // Cells turned the wrong way round (Gmsh keeps the orientation of a
    // clockwise curve loop, other tools list clockwise cells) are turned
    // over; check_cells() refuses what is still inverted or degenerate.
    try
      {
        GridTools::invert_cells_with_negative_measure(mesh.vertices,
                                                      mesh.cells);
      }
    catch (const std::exception &)
      {
        AssertThrow(false,
                    ExcMessage("Mesh/File: '" + file +
                               "' has a cell that is degenerate or not "
                               "convex"));
      }

    finish(mesh, triangulation);
  }



  template <int dim>
  void
  MeshInput<dim>::finish(mesh_readers::Description<dim> &mesh,
                         Triangulation<dim>             &triangulation) const
  {
    bool simplices = false, others = false;
    for (const auto &cell : mesh.cells)
      (cell.vertices.size() == dim + 1 ? simplices : others) = true;
    if constexpr (dim == 2)
      {
        if (simplices && (others || split_triangles || adaptive))
          mesh_readers::split_into_quadrilaterals(mesh, circular_boundaries);
      }
    else
      AssertThrow(!simplices || !adaptive,
                  ExcMessage("Refinement/Strategy: a tetrahedral mesh cannot "
                             "be refined adaptively (deal.II 9.4 has no "
                             "hanging nodes on simplices); use global "
                             "refinement or a hexahedral mesh"));
    try
      {
        triangulation.create_triangulation(mesh.vertices,
                                           mesh.cells,
                                           mesh.subcells);
      }
    catch (const std::exception &exc)
      {
        AssertThrow(false,
                    ExcMessage((source == Source::file
                                  ? "Mesh/File: '" + file + "'"
                                  : std::string("Mesh/Rectangles: the mesh")) +
                               " is not a valid mesh (" +
                               input::one_line(exc.what()) + ")"));
      }
  }



  template <int dim>
  void
  MeshInput<dim>::make_rectangles(Triangulation<dim> &triangulation) const
  {
    if constexpr (dim != 2)
      {
        // scene_dimension() gives 2 for Source = rectangles.
        (void)triangulation;
        AssertThrow(false, ExcInternalError());
      }
    else
      make_rectangles_2d(triangulation);
  }



  template <int dim>
  void
  MeshInput<dim>::make_rectangles_2d(Triangulation<2> &triangulation) const
  {
    // Vertices are shared within a group of rectangles (bonded) and never
    // between groups (contact), which GridGenerator::merge_triangulations
    // cannot express; so the cells are listed here directly.
    mesh_readers::Description<2> mesh;
    std::vector<Point<2>>       &vertices = mesh.vertices;
    std::map<std::pair<unsigned int, std::pair<long, long>>, unsigned int>
           vertex_index;
    double h = std::numeric_limits<double>::max();
    for (const Rectangle &rect : rectangles)
      h = std::min({h,
                    (rect.upper[0] - rect.lower[0]) / rect.n_x,
                    (rect.upper[1] - rect.lower[1]) / rect.n_y});
    // Coincident vertices are found by coordinates rounded far below the
    // smallest cell size.
    const double scale = 1e6 / h;
    for (unsigned int r = 0; r < rectangles.size(); ++r)
      {
        const Rectangle          &rect = rectangles[r];
        std::vector<unsigned int> index((rect.n_x + 1) * (rect.n_y + 1));
        for (unsigned int j = 0; j <= rect.n_y; ++j)
          for (unsigned int i = 0; i <= rect.n_x; ++i)
            {
              const Point<2> p(rect.lower[0] +
                                 (rect.upper[0] - rect.lower[0]) * i / rect.n_x,
                               rect.lower[1] + (rect.upper[1] - rect.lower[1]) *
                                                 j / rect.n_y);
              const auto     key =
                std::make_pair(rect.group,
                               std::make_pair(std::lround(p[0] * scale),
                                              std::lround(p[1] * scale)));
              const auto it = vertex_index.find(key);
              if (it != vertex_index.end())
                index[j * (rect.n_x + 1) + i] = it->second;
              else
                {
                  vertex_index[key]             = vertices.size();
                  index[j * (rect.n_x + 1) + i] = vertices.size();
                  vertices.push_back(p);
                }
            }
        for (unsigned int j = 0; j < rect.n_y; ++j)
          for (unsigned int i = 0; i < rect.n_x; ++i)
            {
              const unsigned int a = index[j * (rect.n_x + 1) + i],
                                 b = index[j * (rect.n_x + 1) + i + 1],
                                 c = index[(j + 1) * (rect.n_x + 1) + i],
                                 d = index[(j + 1) * (rect.n_x + 1) + i + 1];
              const bool split =
                rectangle_cells == RectangleCells::triangles ||
                (rectangle_cells == RectangleCells::mixed && (i + j) % 2 == 1);
              // Two counter-clockwise triangles cut along the diagonal a-d,
              // or one quadrilateral.
              for (const auto &corners :
                   split ? std::vector<std::vector<unsigned int>>{{a, b, d},
                                                                  {a, d, c}}
                         : std::vector<std::vector<unsigned int>>{{a, b, c, d}})
                {
                  CellData<2> cell(corners.size());
                  cell.vertices    = corners;
                  cell.material_id = rect.material_id;
                  mesh.cells.push_back(cell);
                }
            }
      }
    if constexpr (dim == 2)
      finish(mesh, triangulation);

    // Boundary ids by the side of the cell's rectangle each boundary face
    // lies on.
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const Point<2> centre = cell->center();
        const auto     rect   = *std::find_if(
          rectangles.begin(), rectangles.end(), [&](const Rectangle &r) {
            return r.material_id == cell->material_id() &&
                   centre[0] > r.lower[0] && centre[0] < r.upper[0] &&
                   centre[1] > r.lower[1] && centre[1] < r.upper[1];
          });
        const double tol = 1e-8 * cell->diameter();
        for (const unsigned int f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const Point<2> c = cell->face(f)->center();
              if (std::abs(c[0] - rect.lower[0]) < tol)
                cell->face(f)->set_boundary_id(rect.boundary_ids[0]);
              else if (std::abs(c[0] - rect.upper[0]) < tol)
                cell->face(f)->set_boundary_id(rect.boundary_ids[1]);
              else if (std::abs(c[1] - rect.lower[1]) < tol)
                cell->face(f)->set_boundary_id(rect.boundary_ids[2]);
              else
                cell->face(f)->set_boundary_id(rect.boundary_ids[3]);
            }
      }
  }



  template <int dim>
  std::vector<unsigned int>
  compute_body_ids(const Triangulation<dim> &triangulation,
                   unsigned int             &n_bodies)
  {
    // Union-find over vertices: cells that share a vertex are one body.
    std::vector<unsigned int> parent(triangulation.n_vertices());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&parent](unsigned int v) {
      while (parent[v] != v)
        v = parent[v] = parent[parent[v]];
      return v;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      for (const unsigned int v : cell->vertex_indices())
        parent[find(cell->vertex_index(v))] = find(cell->vertex_index(0));

    std::vector<unsigned int>            body(triangulation.n_active_cells());
    std::map<unsigned int, unsigned int> number;
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int root = find(cell->vertex_index(0));
        const auto         it   = number.emplace(root, number.size()).first;
        body[cell->active_cell_index()] = it->second;
      }
    n_bodies = number.size();
    return body;
  }


  template class MeshInput<2>;
  template class MeshInput<3>;
  template void
  check_cells(const Triangulation<2> &);
  template void
  check_cells(const Triangulation<3> &);
  template std::vector<unsigned int>
  compute_body_ids(const Triangulation<2> &, unsigned int &);
  template std::vector<unsigned int>
  compute_body_ids(const Triangulation<3> &, unsigned int &);
} // namespace knee_contact
