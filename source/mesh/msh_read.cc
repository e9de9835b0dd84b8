// The cells of a checked ASCII .msh file, as deal.II's GridIn makes them:
// gmsh_input::read_msh().
#include <knee_contact/mesh/gmsh_input.h>

#include <deal.II/base/geometry_info.h>

#include <deal.II/grid/grid_tools.h>

#include <array>
#include <charconv>
#include <stdexcept>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

namespace knee_contact
{
  namespace gmsh_input
  {
    namespace
    {
      // The words and numbers of a .msh text, read in place (no copy of the
      // text, no stream). Why not GridIn's std::istream: its formatted reads
      // and a std::map lookup per element node took a quarter of a 1e6-DoF
      // mesh's dry run (perf, 2026-12-03 and 2026-12-06).
      class Words
      {
      public:
        explicit Words(const std::string_view text)
          : text(text)
        {}

        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(what);
        }

        std::string_view
        word()
        {
          while (at < text.size() && is_space(text[at]))
            ++at;
          const std::size_t begin = at;
          while (at < text.size() && !is_space(text[at]))
            ++at;
          if (begin == at)
            fail("it ends early");
          return text.substr(begin, at - begin);
        }

        void
        expect(const std::string_view what)
        {
          if (word() != what)
            fail("no " + std::string(what) + " where expected");
        }

        long long
        integer()
        {
          const std::string_view w     = number();
          long long              value = 0;
          const auto [end, error] =
            std::from_chars(w.data(), w.data() + w.size(), value);
          if (error != std::errc() || end != w.data() + w.size())
            fail("'" + std::string(w) + "' is not an integer");
          return value;
        }

        // An integer that counts something: not negative.
        long long
        count()
        {
          const long long n = integer();
          if (n < 0)
            fail("a negative count");
          return n;
        }

        double
        real()
        {
          const std::string_view w     = number();
          double                 value = 0;
          const auto [end, error] =
            std::from_chars(w.data(), w.data() + w.size(), value);
          if (error != std::errc() || end != w.data() + w.size())
            fail("'" + std::string(w) + "' is not a number");
          return value;
        }

        // Past the end of section @p name ("$End" + name).
        void
        skip_section(const std::string_view name)
        {
          const std::string end = "$End" + std::string(name);
          while (word() != end)
            ;
        }

      private:
        // A word without the '+' that strtod, which GridIn's stream calls,
        // takes and from_chars does not.
        std::string_view
        number()
        {
          const std::string_view w = word();
          return w.size() > 1 && w[0] == '+' ? w.substr(1) : w;
        }

        static bool
        is_space(const char c)
        {
          return c == ' ' || c == '\n' || c == '\r' || c == '\t' || c == '\f' ||
                 c == '\v';
        }

        std::string_view text;
        std::size_t      at = 0;
      };



      // The index of each node tag in the order of $Nodes: an array over
      // the tags' range where Gmsh numbers densely, a hash map for sparse or
      // negative tags (check_msh() made sure they are unique, in int).
      class NodeIndex
      {
      public:
        void
        reserve(const long long          smallest,
                const long long          largest,
                const unsigned long long n_nodes)
        {
          if (largest >= smallest &&
              static_cast<unsigned long long>(largest - smallest) <
                16 * n_nodes + 1024)
            {
              first = smallest;
              dense.assign(largest - smallest + 1,
                           numbers::invalid_unsigned_int);
            }
        }

        void
        add(const long long tag, const unsigned int index)
        {
          if (in_dense(tag))
            dense[tag - first] = index;
          else
            sparse[tag] = index;
        }

        unsigned int
        operator()(const long long tag, const Words &words) const
        {
          unsigned int index = numbers::invalid_unsigned_int;
          if (in_dense(tag))
            index = dense[tag - first];
          else if (const auto it = sparse.find(tag); it != sparse.end())
            index = it->second;
          if (index == numbers::invalid_unsigned_int)
            words.fail("node " + std::to_string(tag) + " is not in $Nodes");
          return index;
        }

      private:
        bool
        in_dense(const long long tag) const
        {
          return tag >= first &&
                 static_cast<unsigned long long>(tag - first) < dense.size();
        }

        long long                                   first = 0;
        std::vector<unsigned int>                   dense;
        std::unordered_map<long long, unsigned int> sparse;
      };



      // A $Nodes or $Elements header: 4.1's 'blocks count smallest-tag
      // largest-tag', 2.2's 'count' (one block, tags from 1).
      struct Header
      {
        long long n_blocks = 1, n = 0, smallest = 1, largest = 0;
      };

      Header
      header(Words &words, const bool v4)
      {
        Header h;
        if (v4)
          {
            h.n_blocks = words.count();
            h.n        = words.count();
            h.smallest = words.integer();
            h.largest  = words.integer();
          }
        else
          h.largest = h.n = words.count();
        return h;
      }



      // The sections of a .msh text in the order GridIn reads them, into
      // a description.
      template <int dim>
      class MshText
      {
      public:
        MshText(const std::string_view text)
          : words(text)
        {
          words.expect("$MeshFormat");
          const std::string version(words.word());
          v4 = version == "4.1";
          if (!v4 && version != "2.2" && version != "2")
            words.fail("format version " + version);
          words.word();
          words.word();
          words.expect("$EndMeshFormat");
          // GridIn stops after $Elements.
          for (bool done = false; !done;)
            {
              const std::string_view section = words.word();
              if (section == "$Entities" && v4)
                entities();
              else if (section == "$Nodes")
                nodes();
              else if (section == "$Elements")
                {
                  elements();
                  done = true;
                }
              else if (section.size() > 1 && section[0] == '$')
                words.skip_section(section.substr(1));
              else
                words.fail("'" + std::string(section) + "' outside a section");
            }
          if (mesh.cells.empty())
            words.fail("no cells");
        }

        mesh_readers::Description<dim> mesh;
        bool                           hypercubes = false, simplices = false;

      private:
        // 4.1: each entity's physical group (0 without, as in GridIn).
        void
        entities()
        {
          long long n[4];
          for (auto &count : n)
            count = words.count();
          for (unsigned int d = 0; d < 4; ++d)
            for (long long e = 0; e < n[d]; ++e)
              {
                const long long tag = words.integer();
                for (unsigned int k = 0; k < (d == 0 ? 3 : 6); ++k)
                  words.real();
                const long long n_physical = words.count();
                if (n_physical > 1)
                  words.fail("entity " + std::to_string(tag) +
                             " in several physical groups");
                long long group = 0;
                for (long long k = 0; k < n_physical; ++k)
                  group = words.integer();
                physical[d][tag] = group;
                if (d > 0)
                  for (long long k = words.count(); k > 0; --k)
                    words.integer();
              }
          words.expect("$EndEntities");
        }

        void
        nodes()
        {
          const Header h = header(words, v4);
          node_index.reserve(h.smallest, h.largest, h.n);
          mesh.vertices.reserve(h.n);
          std::vector<long long> tags;
          for (long long b = 0; b < h.n_blocks; ++b)
            {
              long long entity_dim = 0, parametric = 0, n = h.n;
              if (v4)
                {
                  entity_dim = words.integer();
                  words.integer();
                  parametric = words.integer();
                  n          = words.count();
                  tags.resize(n);
                  for (auto &tag : tags)
                    tag = words.integer();
                }
              for (long long i = 0; i < n; ++i)
                {
                  const long long tag = v4 ? tags[i] : words.integer();
                  double          x[3];
                  for (double &x_d : x)
                    x_d = words.real();
                  // A parametric node's coordinates on its entity.
                  for (long long k = 0; parametric != 0 && k < entity_dim; ++k)
                    words.real();
                  Point<dim> point;
                  for (unsigned int d = 0; d < dim; ++d)
                    point[d] = x[d];
                  node_index.add(tag, mesh.vertices.size());
                  mesh.vertices.push_back(point);
                }
            }
          words.expect("$EndNodes");
        }

        void
        elements()
        {
          const Header h = header(words, v4);
          for (long long b = 0; b < h.n_blocks; ++b)
            {
              long long type = 0, n = h.n, id = 0;
              if (v4)
                {
                  const long long entity_dim = words.integer();
                  const long long entity     = words.integer();
                  type                       = words.integer();
                  n                          = words.count();
                  if (entity_dim < 0 || entity_dim > 3)
                    words.fail("entity dimension " +
                               std::to_string(entity_dim));
                  const auto it = physical[entity_dim].find(entity);
                  id = it == physical[entity_dim].end() ? 0 : it->second;
                }
              for (long long i = 0; i < n; ++i)
                {
                  words.integer();
                  if (!v4)
                    {
                      // type n_tags tags...: the first tag is the physical
                      // group.
                      type                   = words.integer();
                      const long long n_tags = words.count();
                      id                     = 0;
                      for (long long k = 0; k < n_tags; ++k)
                        {
                          const long long tag = words.integer();
                          if (k == 0)
                            id = tag;
                        }
                    }
                  element(type, id);
                }
            }
          words.expect("$EndElements");
        }

        // An element's nodes: a cell of material @p id, or a boundary
        // face (a line; in 3D a triangle or quadrilateral) of boundary
        // id @p id.
        void
        element(const long long type, const long long id)
        {
          const unsigned int n_v = element_kind(type).first;
          if (n_v == 0)
            words.fail("element type " + std::to_string(type));
          unsigned int v[8];
          for (unsigned int k = 0; k < n_v; ++k)
            v[k] = node_index(words.integer(), words);
          const bool cell = (dim == 2 && (type == 2 || type == 3)) ||
                            (dim == 3 && (type == 4 || type == 5));
          const bool hypercube = type == 3 || type == 5;
          if (cell)
            {
              (hypercube ? hypercubes : simplices) = true;
              CellData<dim> data(n_v);
              // deal.II numbers a quadrilateral's or a hexahedron's
              // vertices lexicographically.
              for (unsigned int k = 0; k < n_v; ++k)
                data
                  .vertices[hypercube ? GeometryInfo<dim>::ucd_to_deal[k] : k] =
                  v[k];
              data.material_id = static_cast<types::material_id>(id);
              mesh.cells.push_back(std::move(data));
            }
          else if (type == 1)
            {
              CellData<1> line;
              line.vertices    = {v[0], v[1]};
              line.boundary_id = static_cast<types::boundary_id>(id);
              mesh.subcells.boundary_lines.push_back(line);
            }
          else if (dim == 3 && (type == 2 || type == 3))
            {
              (hypercube ? hypercubes : simplices) = true;
              CellData<2> face(n_v);
              for (unsigned int k = 0; k < n_v; ++k)
                face.vertices[k] = v[k];
              face.boundary_id = static_cast<types::boundary_id>(id);
              mesh.subcells.boundary_quads.push_back(std::move(face));
            }
          else if (type != 15)
            words.fail("element type " + std::to_string(type) + " in a " +
                       std::to_string(dim) + "D mesh");
        }

        Words                                                   words;
        bool                                                    v4 = false;
        std::array<std::unordered_map<long long, long long>, 4> physical;
        NodeIndex                                               node_index;
      };
    } // namespace



    template <int dim>
    mesh_readers::Description<dim>
    read_msh(const std::string_view text)
    {
      MshText<dim> read(text);
      auto        &mesh = read.mesh;
      // GridIn's clean-up before it makes the triangulation, in its order:
      // a mesh of quadrilaterals or hexahedra only loses its unused
      // vertices and has its cells ordered consistently; cells turned
      // inside out are turned over.
      if (read.hypercubes && !read.simplices)
        {
          GridTools::delete_unused_vertices(mesh.vertices,
                                            mesh.cells,
                                            mesh.subcells);
          GridTools::invert_cells_with_negative_measure(mesh.vertices,
                                                        mesh.cells);
          GridTools::consistently_order_cells(mesh.cells);
        }
      else if (read.simplices)
        GridTools::invert_cells_with_negative_measure(mesh.vertices,
                                                      mesh.cells);
      return std::move(mesh);
    }



    template mesh_readers::Description<2>
    read_msh<2>(const std::string_view);
    template mesh_readers::Description<3>
    read_msh<3>(const std::string_view);
  } // namespace gmsh_input
} // namespace knee_contact
