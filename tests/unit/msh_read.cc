// gmsh_input::read_msh() against deal.II's GridIn::read_msh(std::istream &),
// the reader it replaces: on meshes gmsh makes of the project's .geo files
// in both formats it reads (2.2 and 4.1), 2D and 3D, triangles,
// quadrilaterals, tetrahedra, hexahedra and a mix, one body and several,
// with boundary lines in 3D, and on the same 2.2 file with sparse and
// negative node tags, the two triangulations are the same: every vertex
// bit for bit, every cell's vertices, material and manifold id in the same
// order, every face's and (3D) line's boundary id. A 4.1 file with
// parametric coordinates (which GridIn misreads on curves) gives the
// triangulation of the same mesh without them.
#include <knee_contact/base/external_program.h>
#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/tria.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

using namespace dealii;
using namespace knee_contact;

namespace
{
  const std::string folder =
    (std::filesystem::temp_directory_path() / "knee_contact_msh_read").string();

  // gmsh -dim on @p geo with @p arguments into folder/name.
  std::string
  mesh(const std::string              &geo,
       const std::vector<std::string> &arguments,
       const std::string              &name)
  {
    const std::string        msh     = folder + "/" + name;
    std::vector<std::string> command = {"gmsh", "-v", "0", "-o", msh};
    command.insert(command.end(), arguments.begin(), arguments.end());
    command.push_back(geo);
    const ProgramResult result = run_program(command, msh + ".log", 120);
    AssertThrow(result.exit_code == 0, ExcMessage("gmsh failed on " + geo));
    return msh;
  }

  // The 2.2 file @p msh with node tag t written as 7919 t - 50000: sparse,
  // the first ones negative.
  std::string
  sparse_tags(const std::string &msh)
  {
    std::ifstream      in(msh);
    std::ostringstream out;
    std::string        line;
    const auto         tag = [](const std::string &t) {
      return std::to_string(7919LL * std::stoll(t) - 50000);
    };
    enum
    {
      other,
      nodes,
      elements
    } section       = other;
    bool count_line = false;
    while (std::getline(in, line))
      {
        std::istringstream       fields(line);
        std::vector<std::string> f;
        for (std::string w; fields >> w;)
          f.push_back(w);
        if (line == "$Nodes" || line == "$Elements")
          {
            section    = line == "$Nodes" ? nodes : elements;
            count_line = true;
          }
        else if (line.rfind("$End", 0) == 0)
          section = other;
        else if (count_line)
          count_line = false;
        else if (section == nodes)
          f[0] = tag(f[0]);
        else if (section == elements)
          for (std::size_t k = 3 + std::stoul(f[2]); k < f.size(); ++k)
            f[k] = tag(f[k]);
        if (section != other && !f.empty() && f[0][0] != '$')
          {
            for (std::size_t k = 0; k < f.size(); ++k)
              out << (k ? " " : "") << f[k];
            out << "\n";
          }
        else
          out << line << "\n";
      }
    const std::string result = msh + ".sparse.msh";
    std::ofstream(result) << out.str();
    return result;
  }

  template <int dim>
  void
  grid_in(const std::string &msh, Triangulation<dim> &tria)
  {
    GridIn<dim>   in(tria);
    std::ifstream file(msh);
    in.read_msh(file);
  }

  template <int dim>
  void
  read(const std::string &msh, Triangulation<dim> &tria)
  {
    const mesh_readers::internal::MappedFile text(msh);
    const auto mesh = gmsh_input::read_msh<dim>(text.text());
    tria.create_triangulation(mesh.vertices, mesh.cells, mesh.subcells);
  }

  template <int dim>
  bool
  same(const Triangulation<dim> &a, const Triangulation<dim> &b)
  {
    if (a.n_vertices() != b.n_vertices() ||
        a.get_vertices() != b.get_vertices() ||
        a.n_active_cells() != b.n_active_cells())
      return false;
    auto y = b.begin_active();
    for (auto x = a.begin_active(); x != a.end(); ++x, ++y)
      {
        if (x->reference_cell() != y->reference_cell() ||
            x->material_id() != y->material_id() ||
            x->manifold_id() != y->manifold_id())
          return false;
        for (const unsigned int v : x->vertex_indices())
          if (x->vertex_index(v) != y->vertex_index(v))
            return false;
        for (const unsigned int f : x->face_indices())
          if (x->face(f)->boundary_id() != y->face(f)->boundary_id())
            return false;
        if (dim == 3)
          for (const unsigned int l : x->line_indices())
            if (x->line(l)->boundary_id() != y->line(l)->boundary_id())
              return false;
      }
    return true;
  }

  template <int dim>
  void
  compare(const std::string &name, const std::string &msh)
  {
    gmsh_input::check_msh(msh);
    Triangulation<dim> a, b;
    grid_in(msh, a);
    read(msh, b);
    unsigned int simplices = 0;
    for (const auto &cell : a.active_cell_iterators())
      simplices += cell->reference_cell().is_simplex();
    std::cout << name << ": " << simplices << " simplices, "
              << a.n_active_cells() - simplices << " others, " << a.n_vertices()
              << " vertices, GridIn's triangulation "
              << (same(a, b) ? "yes" : "NO") << std::endl;
  }
} // namespace

namespace
{
  // A mesh gmsh makes of a .geo: its name, dimension, file and arguments.
  struct Case
  {
    std::string              name;
    int                      dim;
    std::string              geo;
    std::vector<std::string> arguments;
  };
} // namespace

int
main()
{
  std::filesystem::remove_all(folder);
  std::filesystem::create_directories(folder);
  const std::string       meshes = SOURCE_DIR "/../meshes/";
  const std::string       prm    = SOURCE_DIR "/../../prm/";
  const std::vector<Case> cases  = {
     {"triangles (patch stack, two bodies)", 2, meshes + "patch_stack", {}},
     {"quadrilaterals (Hertz, two bodies)", 2, prm + "hertz", {"-clscale", "4"}},
     {"quadrilaterals (knee, sagittal)", 2, prm + "knee", {"-clscale", "4"}},
     {"hexahedra (block, two materials)",
      3,
      meshes + "block",
      {"-setnumber", "two", "1"}},
     {"tetrahedra (cube)",
      3,
      meshes + "cube",
      {"-setnumber", "hex", "0", "-setnumber", "n", "3"}},
     {"tetrahedra (sphere octant, curved)", 3, meshes + "sphere_octant", {}},
     {"hexahedra on tetrahedra (contact stack)",
      3,
      meshes + "contact_stack_3d",
      {"-setnumber",
       "hex_upper",
       "0",
       "-setnumber",
       "n_lower",
       "2",
       "-setnumber",
       "n_upper",
       "3"}}};
  for (const std::string format : {"msh22", "msh41"})
    for (const Case &c : cases)
      {
        std::vector<std::string> arguments = {c.dim == 2 ? "-2" : "-3",
                                              "-format",
                                              format};
        arguments.insert(arguments.end(),
                         c.arguments.begin(),
                         c.arguments.end());
        const std::string stem =
          std::filesystem::path(c.geo).filename().string();
        const std::string msh =
          mesh(c.geo + ".geo", arguments, stem + "_" + format + ".msh");
        if (c.dim == 2)
          compare<2>(format + " " + c.name, msh);
        else
          compare<3>(format + " " + c.name, msh);
      }
  compare<2>("msh22 triangles, sparse and negative node tags",
             sparse_tags(folder + "/patch_stack_msh22.msh"));
  compare<3>("msh22 hexahedra, sparse and negative node tags",
             sparse_tags(folder + "/block_msh22.msh"));
  compare<2>("msh22 file of the uniaxial block scene",
             SOURCE_DIR "/../scenes/uniaxial_block_msh22.msh");
  compare<2>("msh41 file of the uniaxial block scene",
             SOURCE_DIR "/../scenes/uniaxial_block_msh41.msh");

  // Parametric coordinates: the same triangulation as without.
  const std::string plain      = folder + "/sphere_octant_msh41.msh";
  const std::string parametric = mesh(meshes + "sphere_octant.geo",
                                      {"-3", "-format", "msh41", "-parametric"},
                                      "octant_parametric.msh");
  Triangulation<3>  a, b;
  read(plain, a);
  read(parametric, b);
  std::cout << "msh41 with parametric coordinates: the triangulation "
               "without them "
            << (same(a, b) ? "yes" : "NO") << std::endl;
  std::filesystem::remove_all(folder);
}
