#include <knee_contact/gmsh_input.h>
#include <knee_contact/input.h>
#include <knee_contact/interruption.h>
#include <knee_contact/mesh.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <numeric>

namespace knee_contact
{
  void
  MeshInput::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Mesh");
    prm.declare_entry("Source",
                      "rectangles",
                      Patterns::Selection("rectangles|file"),
                      "Where the mesh comes from: 'file' (Gmsh .msh, or .geo "
                      "meshed by the gmsh program) or 'rectangles' (built in, "
                      "for simple scenes and tests).");
    prm.declare_entry("File",
                      "",
                      Patterns::Anything(),
                      "Gmsh file (.msh or .geo), relative to the scene file. "
                      "Physical surfaces become material ids, physical curves "
                      "boundary ids. Cells must be quadrilaterals (in a .geo: "
                      "Recombine, or Mesh.SubdivisionAlgorithm = 1).");
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
                      "with the centre (x_c, y_c) [m].");
    prm.leave_subsection();
  }



  void
  MeshInput::parse_parameters(ParameterHandler  &prm,
                              const std::string &scene_file)
  {
    prm.enter_subsection("Mesh");
    source = prm.get("Source") == "file" ? Source::file : Source::rectangles;
    file   = input::resolve_path(prm.get("File"), scene_file);
    gmsh_arguments   = gmsh_input::arguments(prm.get("Gmsh arguments"));
    gmsh_time_limit  = prm.get_double("Gmsh time limit");
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
          input::to_point(centre, circles);
      }
    prm.leave_subsection();
  }



  void
  MeshInput::create(Triangulation<2> &triangulation) const
  {
    triangulation.clear();
    if (source == Source::file)
      read_gmsh(triangulation);
    else
      make_rectangles(triangulation);

    AssertThrow(triangulation.n_active_cells() > 0,
                ExcMessage("Mesh: the mesh has no cells"));
    check_cells(triangulation);

    if (rotation_degrees != 0)
      GridTools::rotate(rotation_degrees * numbers::PI / 180, triangulation);

    types::manifold_id manifold = 1;
    for (const auto &[id, centre] : circular_boundaries)
      {
        Point<2> c = centre;
        if (rotation_degrees != 0)
          {
            const double a = rotation_degrees * numbers::PI / 180;
            c = Point<2>(std::cos(a) * centre[0] - std::sin(a) * centre[1],
                         std::sin(a) * centre[0] + std::cos(a) * centre[1]);
          }
        bool found = false;
        for (const auto &face : triangulation.active_face_iterators())
          if (face->at_boundary() && face->boundary_id() == id)
            {
              // PolarManifold puts new vertices at the radius of the
              // face's ends: both must lie on one circle about the centre.
              const double r0 = face->vertex(0).distance(c),
                           r1 = face->vertex(1).distance(c);
              AssertThrow(
                r0 > 0 && std::abs(r0 - r1) <= 1e-6 * std::max(r0, r1) &&
                  face->vertex(0).distance(face->vertex(1)) < std::max(r0, r1),
                ExcMessage("Mesh/Circular boundaries: the edge of boundary "
                           "id " +
                           std::to_string(id) + " from (" +
                           std::to_string(face->vertex(0)[0]) + ", " +
                           std::to_string(face->vertex(0)[1]) + ") to (" +
                           std::to_string(face->vertex(1)[0]) + ", " +
                           std::to_string(face->vertex(1)[1]) +
                           ") is not an arc about the given centre (radii " +
                           std::to_string(r0) + " and " + std::to_string(r1) +
                           ")"));
              face->set_manifold_id(manifold);
              found = true;
            }
        AssertThrow(found,
                    ExcMessage("Mesh/Circular boundaries: the mesh has no "
                               "boundary id " +
                               std::to_string(id)));
        triangulation.set_manifold(manifold, PolarManifold<2>(c));
        ++manifold;
      }

    // Refuse early a mesh the machine cannot hold: about 8 kB per cell for
    // matrix, factorisation and vectors (measured: 1.8 GB for 236 544 cells
    // with contact).
    const double n_cells =
      triangulation.n_active_cells() * std::pow(4., n_refinements);
    const double needed    = 8e3 * n_cells;
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
                  "Mesh/Global refinements: " + std::to_string(n_refinements) +
                  " refinements give about " +
                  std::to_string(static_cast<long long>(n_cells)) +
                  " cells, needing about " +
                  std::to_string(static_cast<long long>(needed / 1e9)) +
                  " GB; this machine has " +
                  std::to_string(available / 1e9).substr(0, 5) +
                  " GB available"));
    triangulation.refine_global(n_refinements);
    if (n_refinements > 0)
      check_cells(triangulation);
  }



  void
  check_cells(const Triangulation<2> &triangulation)
  {
    // The Jacobian of a bilinear quadrilateral is positive everywhere iff
    // the cross products of the edges at all four corners are (deal.II's
    // vertex order 0 1 3 2 runs counter-clockwise). Checked on every mesh
    // the program solves on: refinement on a circle that does not fit the
    // vertices can fold cells.
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int ring[4] = {0, 1, 3, 2};
        for (unsigned int k = 0; k < 4; ++k)
          {
            const Tensor<1, 2> a =
              cell->vertex(ring[(k + 1) % 4]) - cell->vertex(ring[k]);
            const Tensor<1, 2> b =
              cell->vertex(ring[(k + 3) % 4]) - cell->vertex(ring[k]);
            AssertThrow(a[0] * b[1] - a[1] * b[0] > 1e-12 * a.norm() * b.norm(),
                        ExcMessage("Mesh: cell at (" +
                                   std::to_string(cell->center()[0]) + ", " +
                                   std::to_string(cell->center()[1]) +
                                   ") is inverted, degenerate or not convex" +
                                   (cell->level() > 0
                                      ? " after refinement (level " +
                                          std::to_string(cell->level()) + ")"
                                      : std::string())));
          }
      }
  }



  void
  MeshInput::read_gmsh(Triangulation<2> &triangulation) const
  {
    std::string msh = file;
    std::string temporary_folder;
    if (std::filesystem::path(file).extension() == ".geo")
      {
        // Mesh the .geo with the gmsh program into a private temporary
        // folder (removed on Ctrl-C too).
        std::string folder =
          (std::filesystem::temp_directory_path() / "knee_contact_XXXXXX")
            .string();
        AssertThrow(mkdtemp(folder.data()) != nullptr,
                    ExcMessage("cannot create a temporary folder for gmsh"));
        temporary_folder = folder;
        interruption::register_folder(temporary_folder);
        msh = folder + "/mesh.msh";
        try
          {
            gmsh_input::mesh(file, msh, gmsh_arguments, gmsh_time_limit);
          }
        catch (...)
          {
            interruption::unregister_folder(temporary_folder);
            std::filesystem::remove_all(temporary_folder);
            throw;
          }
      }
    const auto remove_temporary = [&]() {
      if (!temporary_folder.empty())
        {
          interruption::unregister_folder(temporary_folder);
          std::filesystem::remove_all(temporary_folder);
        }
    };

    // deal.II's reader trusts its input; check the file first.
    try
      {
        gmsh_input::check_msh(msh);
      }
    catch (const std::exception &exc)
      {
        remove_temporary();
        // Name the user's .geo, not the temporary file.
        std::string message = exc.what();
        const auto  at      = message.find("'" + msh + "'");
        if (msh != file && at != std::string::npos)
          message.replace(at,
                          msh.size() + 2,
                          "the mesh gmsh made of '" + file + "',");
        AssertThrow(false, ExcMessage(message));
      }

    GridIn<2> grid_in;
    grid_in.attach_triangulation(triangulation);
    std::ifstream in(msh);
    try
      {
        grid_in.read_msh(in);
      }
    catch (const std::exception &exc)
      {
        remove_temporary();
        AssertThrow(false,
                    ExcMessage("Mesh/File: cannot read '" + file +
                               "' as a Gmsh mesh (" +
                               input::one_line(exc.what()) + ")"));
      }
    remove_temporary();
    AssertThrow(triangulation.all_reference_cells_are_hyper_cube(),
                ExcMessage("Mesh/File: '" + file +
                           "' has triangles; knee_contact needs "
                           "quadrilaterals (Recombine the surfaces)"));

    // Gmsh orients the cells of a surface whose curve loop runs clockwise
    // clockwise too, and GridIn keeps that; deal.II needs counter-clockwise
    // cells, so rebuild the mesh with such cells turned over.
    auto [vertices, cells, subcell_data] =
      GridTools::get_coarse_mesh_description(triangulation);
    GridTools::invert_all_negative_measure_cells(vertices, cells);
    triangulation.clear();
    triangulation.create_triangulation(vertices, cells, subcell_data);
  }



  void
  MeshInput::make_rectangles(Triangulation<2> &triangulation) const
  {
    // Vertices are shared within a group of rectangles (bonded) and never
    // between groups (contact), which GridGenerator::merge_triangulations
    // cannot express; so the cells are listed here directly.
    std::vector<Point<2>>    vertices;
    std::vector<CellData<2>> cells;
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
              CellData<2> cell;
              cell.vertices    = {index[j * (rect.n_x + 1) + i],
                                  index[j * (rect.n_x + 1) + i + 1],
                                  index[(j + 1) * (rect.n_x + 1) + i],
                                  index[(j + 1) * (rect.n_x + 1) + i + 1]};
              cell.material_id = rect.material_id;
              cells.push_back(cell);
            }
      }
    triangulation.create_triangulation(vertices, cells, SubCellData());

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



  std::vector<unsigned int>
  compute_body_ids(const Triangulation<2> &triangulation,
                   unsigned int           &n_bodies)
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
} // namespace knee_contact
