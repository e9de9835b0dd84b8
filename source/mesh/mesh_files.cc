#include <knee_contact/base/input.h>
#include <knee_contact/base/interruption.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/mesh_readers.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/manifold_lib.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <stdexcept>
#include <tuple>


// MeshInput's members that read mesh files (Gmsh, and in 2D Abaqus, VTK,
// VTU, UCD), make the built-in rectangles and build the triangulation of a
// description; scene_dimension(), which reads the Gmsh file first.
namespace knee_contact
{
  namespace
  {
    /**
     * A .msh ready to read: the user's file, or the mesh gmsh made of a .geo
     * (or the ASCII copy gmsh wrote of a binary .msh) in a private temporary
     * folder (removed on Ctrl-C too, and when this
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

    /** A private temporary folder for @p result's mesh (removed with it). */
    void
    make_folder(CheckedMsh &result)
    {
      std::string folder =
        (std::filesystem::temp_directory_path() / "knee_contact_XXXXXX")
          .string();
      AssertThrow(mkdtemp(folder.data()) != nullptr,
                  ExcMessage("cannot create a temporary folder for gmsh"));
      interruption::register_folder(folder);
      result.folder = folder;
      result.msh    = folder + "/mesh.msh";
    }

    /** checked_msh() on this process alone. */
    std::unique_ptr<CheckedMsh>
    check_here(const std::string              &file,
               const std::vector<std::string> &arguments,
               const gmsh_input::Limits       &limits)
    {
      auto result       = std::make_unique<CheckedMsh>();
      result->file      = file;
      result->arguments = arguments;
      result->msh       = file;
      const bool geo    = std::filesystem::path(file).extension() == ".geo";
      if (geo || gmsh_input::is_binary_msh(file))
        {
          make_folder(*result);
          if (geo)
            gmsh_input::mesh(file, result->msh, arguments, limits);
          else
            gmsh_input::convert(file, result->msh, limits);
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

    /**
     * @p file (a .msh or a .geo gmsh meshes with @p arguments) checked and
     * ready to read. Under mpirun rank 0 alone runs gmsh and checks; the
     * others take its outcome: its failure (the same one-line error, said
     * once by rank 0), the user's .msh as checked, or the bytes of the mesh
     * gmsh made, written into a folder of their own (no file system shared
     * between the ranks' machines is assumed). Every rank running gmsh took
     * N gmsh processes, each allowed a quarter of the machine's memory, and
     * N times gmsh's time where ranks outnumber cores. Inside
     * parallel::on_first_rank()'s work (rank 0 making a mesh alone, to be
     * distributed) rank 0 checks here, alone.
     */
    std::unique_ptr<CheckedMsh>
    checked_msh(const std::string              &file,
                const std::vector<std::string> &arguments,
                const gmsh_input::Limits       &limits)
    {
      if (kept_msh && kept_msh->file == file &&
          kept_msh->arguments == arguments)
        {
          if (!parallel::working_alone())
            return std::move(kept_msh);
          // Rank 0 alone reads it but keeps it, as every other rank keeps
          // its copy: a mesh then kept whole is made on every rank alike.
          auto view       = std::make_unique<CheckedMsh>();
          view->file      = kept_msh->file;
          view->arguments = kept_msh->arguments;
          view->msh       = kept_msh->msh;
          view->dim       = kept_msh->dim;
          return view;
        }
      if (parallel::n_ranks() == 1 || parallel::working_alone())
        return check_here(file, arguments, limits);

      // Rank 0's outcome: its failure on every rank, or its checked file.
      std::unique_ptr<CheckedMsh> result;
      parallel::on_first_rank(
        [&]() {
          result = check_here(file, arguments, limits);
          return std::string();
        },
        "mesh or check '" + file + "'");

      // The dimension, and the mesh gmsh made (empty: the user's file).
      std::string dim, made;
      if (parallel::rank() == 0)
        {
          dim = std::to_string(result->dim);
          if (result->msh != file)
            {
              std::ifstream in(result->msh, std::ios::binary);
              made.assign(std::istreambuf_iterator<char>(in), {});
              AssertThrow(in.good() || in.eof(),
                          ExcMessage("cannot read the mesh gmsh made of '" +
                                     file + "'"));
            }
        }
      parallel::broadcast_from_first(dim);
      parallel::broadcast_from_first(made);
      if (parallel::rank() == 0)
        return result;
      result            = std::make_unique<CheckedMsh>();
      result->file      = file;
      result->arguments = arguments;
      result->msh       = file;
      result->dim       = std::stoul(dim);
      if (!made.empty())
        {
          make_folder(*result);
          std::ofstream out(result->msh, std::ios::binary);
          out.write(made.data(), made.size());
          out.close();
          AssertThrow(out.good(),
                      ExcMessage("cannot write the mesh gmsh made of '" + file +
                                 "' into a temporary folder"));
        }
      return result;
    }
  } // namespace



  unsigned int
  scene_dimension(const MeshInput<2> &mesh_input, const std::string &scene_file)
  {
    const bool from_file = mesh_input.source == MeshInput<2>::Source::file;
    const std::string file =
      input::resolve_path(mesh_input.entries.file, scene_file);
    const auto arguments =
      gmsh_input::arguments(mesh_input.entries.gmsh_arguments);
    const gmsh_input::Limits limits{mesh_input.gmsh_time_limit,
                                    mesh_input.gmsh_memory_limit};
    const auto extension = std::filesystem::path(file).extension();
    // Anything else is 2D; a missing file is reported by MeshInput.
    if (!from_file ||
        (extension != ".msh" && extension != ".geo" && extension != ".inp") ||
        !std::filesystem::is_regular_file(file) || !std::ifstream(file).good())
      return 2;
    if (extension == ".inp")
      return mesh_readers::abaqus_dimension(file);
    kept_msh = checked_msh(file, arguments, limits);
    return kept_msh->dim;
  }



  void
  release_scene_mesh()
  {
    kept_msh.reset();
  }



  template <int dim>
  std::map<types::material_id, mesh_readers::DeckMaterial>
  MeshInput<dim>::deck_materials() const
  {
    AssertThrow(source == Source::file &&
                  std::filesystem::path(file).extension() == ".inp",
                ExcMessage("Materials/Elastic constants: 'mesh file' takes "
                           "E and nu from an Abaqus deck (.inp), and "
                           "Mesh/File is " +
                           (source == Source::file ? "'" + file + "'"
                                                   : std::string("not set"))));
    read_deck = std::make_unique<mesh_readers::Description<dim>>(
      mesh_readers::read_abaqus<dim>(file,
                                     abaqus_element_sets,
                                     abaqus_boundary_sets));
    return read_deck->deck_materials;
  }



  template <int dim>
  void
  MeshInput<dim>::read_gmsh(const int           level,
                            Triangulation<dim> &triangulation) const
  {
    // Level L: the mesh size times 2^-L (gmsh's -clscale, on top of one the
    // scene gives).
    std::vector<std::string> arguments = gmsh_arguments;
    if (level != 0)
      {
        const double factor = std::pow(0.5, level);
        const auto   it =
          std::find(arguments.begin(), arguments.end(), "-clscale");
        std::ostringstream scale;
        scale << std::setprecision(17)
              << factor * (it != arguments.end() && it + 1 != arguments.end()
                             ? input::number(*(it + 1)).value_or(1.)
                             : 1.);
        if (it != arguments.end() && it + 1 != arguments.end())
          *(it + 1) = scale.str();
        else
          arguments.insert(arguments.end(), {"-clscale", scale.str()});
      }
    auto msh =
      checked_msh(file,
                  arguments,
                  gmsh_input::Limits{gmsh_time_limit, gmsh_memory_limit});
    AssertThrow(msh->dim == dim, ExcInternalError());
    // An entity in several physical groups: the one the scene names.
    const std::string one_group = gmsh_input::one_group_per_entity(
      msh->msh, file, dim, scene_material_ids, scene_boundary_ids);
    try
      {
        // GridIn's cells, read faster (gmsh_input::read_msh()).
        mesh_readers::Description<dim> mesh;
        if (one_group.empty())
          {
            const mesh_readers::internal::MappedFile text(msh->msh);
            mesh = gmsh_input::read_msh<dim>(text.text());
          }
        else
          mesh = gmsh_input::read_msh<dim>(one_group);
        triangulation.create_triangulation(mesh.vertices,
                                           mesh.cells,
                                           mesh.subcells);
      }
    catch (const std::exception &exc)
      {
        AssertThrow(false,
                    ExcMessage("Mesh/File: cannot read '" + file +
                               "' as a Gmsh mesh (" +
                               input::one_line(exc.what()) + ")"));
      }
  }



  template <int dim>
  void
  MeshInput<dim>::read_file(Triangulation<dim> &triangulation,
                            const int           level) const
  {
    const std::string extension = std::filesystem::path(file).extension();
    AssertThrow(extension == ".inp" ||
                  (abaqus_element_sets.empty() && abaqus_boundary_sets.empty()),
                ExcMessage("Mesh/Abaqus element sets and Abaqus boundary sets "
                           "are for .inp files, not '" +
                           file + "'"));
    mesh_readers::Description<dim> mesh;
    if (extension == ".msh" || extension == ".geo")
      {
        // read_gmsh() makes the triangulation; most Gmsh meshes are
        // ready as read. Only cells to turn over or to split need the
        // description (a second triangulation took 6.3 of the 22 s of
        // reading a mesh of 1.5e6 tetrahedra).
        read_gmsh(level, triangulation);
        if (!needs_split(triangulation) && !any_cell_inverted(triangulation))
          return;
        std::tie(mesh.vertices, mesh.cells, mesh.subcells) =
          GridTools::get_coarse_mesh_description(triangulation);
        triangulation.clear();
      }
    else if (extension == ".inp")
      {
        if (read_deck == nullptr)
          deck_materials();
        mesh = std::move(*read_deck);
        read_deck.reset();
      }
    else if constexpr (dim == 3)
      {
        // scene_dimension() gives 3 for Gmsh and Abaqus files only.
        AssertThrow(false, ExcInternalError());
      }
    else
      {
        if (extension == ".vtk")
          mesh = mesh_readers::read_vtk(file);
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
  bool
  MeshInput<dim>::needs_split(const bool simplices, const bool others) const
  {
    return simplices && (others || adaptive || (dim == 2 && split_triangles));
  }



  template <int dim>
  bool
  MeshInput<dim>::needs_split(const Triangulation<dim> &triangulation) const
  {
    bool simplices = false, others = false;
    for (const auto &cell : triangulation.active_cell_iterators())
      (cell->reference_cell().is_simplex() ? simplices : others) = true;
    return needs_split(simplices, others);
  }



  template <int dim>
  bool
  MeshInput<dim>::any_cell_inverted(const Triangulation<dim> &triangulation)
  {
    // The measure GridTools::invert_cells_with_negative_measure() judges by.
    const auto               &vertices = triangulation.get_vertices();
    std::vector<unsigned int> indices;
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        indices.resize(cell->n_vertices());
        for (const auto k : cell->vertex_indices())
          indices[k] = cell->vertex_index(k);
        if (GridTools::cell_measure<dim>(vertices, indices) < 0)
          return true;
      }
    return false;
  }



  template <int dim>
  void
  MeshInput<dim>::finish(mesh_readers::Description<dim> &mesh,
                         Triangulation<dim>             &triangulation) const
  {
    bool simplices = false, others = false;
    for (const auto &cell : mesh.cells)
      (cell.vertices.size() == dim + 1 ? simplices : others) = true;
    const bool split = needs_split(simplices, others);
    if constexpr (dim == 2)
      {
        if (split)
          mesh_readers::split_into_quadrilaterals(mesh, circular_boundaries);
      }
    try
      {
        if constexpr (dim == 3)
          if (split)
            mesh_readers::split_into_hexahedra(mesh);
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
        const auto     found  = std::find_if(
          rectangles.begin(), rectangles.end(), [&](const Rectangle &r) {
            return r.material_id == cell->material_id() &&
                   centre[0] > r.lower[0] && centre[0] < r.upper[0] &&
                   centre[1] > r.lower[1] && centre[1] < r.upper[1];
          });
        // Only a mesh whose vertices were merged wrongly has such a cell.
        AssertThrow(found != rectangles.end(),
                    ExcMessage("Mesh/Rectangles: the cell at (" +
                               std::to_string(centre[0]) + ", " +
                               std::to_string(centre[1]) +
                               ") lies inside none of the rectangles"));
        const Rectangle &rect = *found;
        const double     tol  = 1e-8 * cell->diameter();
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



#define KNEE_CONTACT_INSTANTIATE(dim)                                        \
  template void MeshInput<dim>::read_gmsh(const int, Triangulation<dim> &)   \
    const;                                                                   \
  template void MeshInput<dim>::read_file(Triangulation<dim> &, const int)   \
    const;                                                                   \
  template void MeshInput<dim>::finish(mesh_readers::Description<dim> &,     \
                                       Triangulation<dim> &) const;          \
  template void MeshInput<dim>::make_rectangles(Triangulation<dim> &) const; \
  template void MeshInput<dim>::make_rectangles_2d(Triangulation<2> &) const;
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
