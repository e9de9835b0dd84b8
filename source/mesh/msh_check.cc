// The checks of an ASCII .msh file (format 2.2 or 4.1) before deal.II's
// GridIn reads it: gmsh_input::check_msh().
#include <knee_contact/base/input.h>
#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>
#include <unordered_set>
#include <vector>

namespace knee_contact
{
  namespace gmsh_input
  {
    namespace
    {
      // The node tags of $Nodes. Why not a hash set alone: a lookup per
      // element node was a tenth of a 1e6-DoF mesh's dry run (2e6
      // tetrahedra, 8e6 lookups; perf, 2026-12-03). Gmsh numbers nodes
      // from 1 without gaps, so tags up to a bound given by the node count
      // go into a bitmap (one bit per tag, at most 16 bits per node); any
      // other tag (sparse numbering, negative) into the hash set.
      class NodeTags
      {
      public:
        // @p n_nodes more nodes to come (a $Nodes section's count, checked
        // against the memory before): the bitmap grows to their bound, and
        // takes the hashed tags it now covers.
        void
        expect(const unsigned long long n_nodes)
        {
          const unsigned long long bound =
            std::min<unsigned long long>(16 * (n_nodes + n_inserted) + 1024,
                                         std::numeric_limits<int>::max() +
                                           1ULL);
          if (bound <= dense.size())
            return;
          dense.resize(bound, false);
          for (auto tag = sparse.begin(); tag != sparse.end();)
            if (*tag >= 0 && static_cast<unsigned long long>(*tag) < bound)
              {
                dense[*tag] = true;
                tag         = sparse.erase(tag);
              }
            else
              ++tag;
        }

        // False if @p tag was there.
        bool
        insert(const long long tag)
        {
          if (tag >= 0 && static_cast<unsigned long long>(tag) < dense.size())
            {
              if (dense[tag])
                return false;
              dense[tag] = true;
              ++n_inserted;
              return true;
            }
          const bool inserted = sparse.insert(tag).second;
          n_inserted += inserted;
          return inserted;
        }

        bool
        contains(const long long tag) const
        {
          if (tag >= 0 && static_cast<unsigned long long>(tag) < dense.size())
            return dense[tag];
          return sparse.count(tag) > 0;
        }

      private:
        std::vector<bool>             dense;
        std::unordered_set<long long> sparse;
        unsigned long long            n_inserted = 0;
      };



      // A .msh read line by line, with the line number for messages.
      class MshReader
      {
      public:
        explicit MshReader(const std::string &file)
          : file(file)
          , in(file)
        {
          std::error_code code;
          size = std::filesystem::file_size(file, code);
          if (!in || code)
            fail("cannot open the file");
        }

        [[noreturn]] void
        fail(const std::string &what) const
        {
          fail_at(line_number, what);
        }

        [[noreturn]] void
        fail_at(const unsigned long line, const std::string &what) const
        {
          throw std::runtime_error("Mesh/File: '" + file + "' line " +
                                   std::to_string(line) + ": " + what);
        }

        unsigned long
        line() const
        {
          return line_number;
        }

        // The next line, split at white space; false at the end.
        bool
        next(std::vector<std::string> &tokens)
        {
          std::string line;
          const auto read = mesh_readers::internal::read_line(in, buffer, line);
          if (read == mesh_readers::internal::LineRead::end)
            return false;
          ++line_number;
          if (read == mesh_readers::internal::LineRead::too_long)
            fail(
              "a line longer than " +
              std::to_string(mesh_readers::internal::max_line_length / 1024) +
              " kB (not a .msh file?)");
          tokens.clear();
          std::istringstream words(line);
          for (std::string w; words >> w;)
            tokens.push_back(w);
          return true;
        }

        std::vector<std::string>
        expect(const std::size_t  n_min,
               const std::size_t  n_max,
               const std::string &what)
        {
          std::vector<std::string> tokens;
          if (!next(tokens))
            fail("the file ends before " + what + " (truncated?)");
          if (tokens.size() < n_min || tokens.size() > n_max)
            fail(
              "expected " + what + ", found " + std::to_string(tokens.size()) +
              " fields" +
              (n_min == n_max ? " instead of " + std::to_string(n_min) : ""));
          return tokens;
        }

        // Nodes to come: the run they ask for must fit in memory (a mesh
        // has at least half as many cells as nodes), checked before they
        // are read and stored.
        void
        check_fits(const unsigned long long n_nodes) const
        {
          check_run_fits(2,
                         n_nodes / 2.,
                         "Mesh/File: '" + file + "' line " +
                           std::to_string(line_number) + ": " +
                           std::to_string(n_nodes) + " nodes");
        }

        // A count; each entry takes at least a few bytes, so a count
        // larger than the file can hold is refused before anyone allocates.
        unsigned long long
        count(const std::string &token, const std::string &what) const
        {
          if (token.empty() || token.size() > 19 ||
              token.find_first_not_of("0123456789") != std::string::npos)
            fail(what + " '" + token + "' is not a non-negative integer");
          const unsigned long long n = std::stoull(token);
          if (n > size / 2 + 1)
            fail(what + " " + token + " is more than the file's " +
                 std::to_string(size) + " bytes can hold");
          return n;
        }

        long long
        tag(const std::string &token, const std::string &what) const
        {
          if (token.empty() || token.size() > 18 ||
              token.find_first_not_of("-0123456789") != std::string::npos)
            fail(what + " '" + token + "' is not an integer");
          const long long value = std::stoll(token);
          // deal.II's reader keeps tags in int.
          if (std::abs(value) > std::numeric_limits<int>::max())
            fail(what + " " + token + " is out of range");
          return value;
        }

        // A node tag of $Nodes, which must not repeat.
        void
        add_node(NodeTags &nodes, const std::string &token) const
        {
          if (!nodes.insert(tag(token, "node tag")))
            fail("node tag " + token + " appears twice");
        }

        // The node tags t[first], ... of element t[0]: each must be in
        // $Nodes.
        void
        check_element_nodes(const NodeTags                 &nodes,
                            const std::vector<std::string> &t,
                            const std::size_t               first) const
        {
          for (std::size_t k = first; k < t.size(); ++k)
            if (!nodes.contains(tag(t[k], "node tag")))
              fail("element " + t[0] + " refers to node " + t[k] +
                   ", which is not in $Nodes");
        }

        void
        coordinate(const std::string &token) const
        {
          if (!input::number(token))
            fail("coordinate '" + token + "' is not a finite number");
        }

        void
        end_of(const std::string &section)
        {
          std::vector<std::string> tokens;
          if (!next(tokens) || tokens.size() != 1 ||
              tokens[0] != "$End" + section)
            fail("expected $End" + section +
                 " (a count does not match the entries, or the header's "
                 "version does not match the body)");
        }

        void
        skip_section(const std::string &section)
        {
          std::vector<std::string> tokens;
          while (next(tokens))
            if (tokens.size() == 1 && tokens[0] == "$End" + section)
              return;
          fail("no $End" + section + " (truncated?)");
        }

        const std::string file;

      private:
        std::ifstream      in;
        std::vector<char>  buffer;
        unsigned long long size        = 0;
        unsigned long      line_number = 0;
      };



      // element_kind(), or the failure that names what is not supported.
      std::pair<unsigned int, unsigned int>
      nodes_and_dimension(const long long type, const MshReader &reader)
      {
        const auto kind = element_kind(type);
        if (kind.first > 0)
          return kind;
        if (type == 6 || type == 7)
          reader.fail(std::string(type == 6 ? "wedges (prisms)" : "pyramids") +
                      " (element type " + std::to_string(type) +
                      ") are not supported; mesh the volumes with "
                      "tetrahedra (4) or hexahedra (5) only");
        reader.fail("element type " + std::to_string(type) +
                    " is not supported (points 15, lines 1, triangles "
                    "2, quadrilaterals 3, tetrahedra 4, hexahedra 5; "
                    "linear elements only)");
      }

      // The cells' dimension (the highest element dimension). Tetrahedra
      // beside hexahedra are read: MeshInput splits such a mesh into
      // hexahedra.
      struct CellKinds
      {
        unsigned int dimension = 0;

        void
        add(const long long type, const MshReader &reader)
        {
          dimension =
            std::max(dimension, nodes_and_dimension(type, reader).second);
        }
      };



      unsigned int
      check_msh2(MshReader &reader)
      {
        CellKinds kinds;
        // A face without a physical group is a cell without a material id
        // if the mesh is 2D, a boundary without an id if it is 3D: known
        // only at the end, so the first one is remembered.
        std::string              untagged_face;
        unsigned long            untagged_line = 0;
        NodeTags                 nodes;
        bool                     have_nodes = false, have_elements = false;
        std::vector<std::string> t;
        while (reader.next(t))
          {
            if (t.empty())
              continue;
            if (t[0] == "$Nodes")
              {
                const auto n =
                  reader.count(reader.expect(1, 1, "the node count")[0],
                               "node count");
                reader.check_fits(n);
                nodes.expect(n);
                for (unsigned long long i = 0; i < n; ++i)
                  {
                    t = reader.expect(4, 4, "a node 'tag x y z'");
                    reader.add_node(nodes, t[0]);
                    for (unsigned int d = 1; d < 4; ++d)
                      reader.coordinate(t[d]);
                  }
                reader.end_of("Nodes");
                have_nodes = true;
              }
            else if (t[0] == "$Elements")
              {
                if (!have_nodes)
                  reader.fail("$Elements before $Nodes");
                const auto n =
                  reader.count(reader.expect(1, 1, "the element count")[0],
                               "element count");
                for (unsigned long long i = 0; i < n; ++i)
                  {
                    t = reader.expect(4, 64, "an element");
                    reader.tag(t[0], "element tag");
                    const long long type = reader.tag(t[1], "element type");
                    const auto [n_v, element_dim] =
                      nodes_and_dimension(type, reader);
                    kinds.add(type, reader);
                    const long long n_tags = reader.tag(t[2], "tag count");
                    if (n_tags < 0 ||
                        t.size() != 3 + static_cast<std::size_t>(n_tags) + n_v)
                      reader.fail("element " + t[0] + " has " +
                                  std::to_string(t.size()) +
                                  " fields, not 3 + tags + nodes");
                    const std::size_t first_node =
                      3 + static_cast<std::size_t>(n_tags);
                    for (std::size_t k = 3; k < first_node; ++k)
                      if (reader.tag(t[k], "element tag") < 0)
                        reader.fail("element " + t[0] + " has a negative tag");
                    const bool untagged = n_tags == 0 || t[3] == "0";
                    if (element_dim == 3 && untagged)
                      reader.fail("cell " + t[0] +
                                  " has no physical group, so no material id "
                                  "(give every volume a Physical Volume)");
                    if (element_dim == 2 && untagged && untagged_face.empty())
                      {
                        untagged_face = t[0];
                        untagged_line = reader.line();
                      }
                    reader.check_element_nodes(nodes, t, first_node);
                  }
                reader.end_of("Elements");
                have_elements = true;
              }
            else if (t[0].size() > 1 && t[0][0] == '$')
              reader.skip_section(t[0].substr(1));
          }
        if (!have_nodes || !have_elements)
          reader.fail("no $Nodes or no $Elements section (truncated?)");
        if (kinds.dimension == 2 && !untagged_face.empty())
          reader.fail_at(untagged_line,
                         "cell " + untagged_face +
                           " has no physical group, so no material id "
                           "(give every surface a Physical Surface)");
        return kinds.dimension;
      }



      unsigned int
      check_msh4(MshReader &reader)
      {
        CellKinds kinds;
        NodeTags  nodes;
        // Entities of the cells' dimension (surfaces in 2D, volumes in 3D:
        // a mesh with volume entities is 3D) without a physical group.
        std::unordered_set<long long> unnamed_surfaces;
        unsigned int                  n_named_surfaces = 0;
        unsigned int                  cell_dim         = 2;
        bool have_entities = false, have_nodes = false, have_elements = false;
        std::vector<std::string> t;
        while (reader.next(t))
          {
            if (t.empty())
              continue;
            if (t[0] == "$Entities")
              {
                t = reader.expect(4, 4, "'numPoints numCurves ...'");
                if (reader.count(t[3], "entity count") > 0)
                  cell_dim = 3;
                for (unsigned int dim = 0; dim < 4; ++dim)
                  {
                    const auto n = reader.count(t[dim], "entity count");
                    for (unsigned long long i = 0; i < n; ++i)
                      {
                        // point: tag x y z n_phys tags...; curves and
                        // surfaces: tag box(6) n_phys tags... n_b tags...
                        const auto e = reader.expect(dim == 0 ? 5 : 9,
                                                     1u << 20,
                                                     "an entity");
                        const std::size_t p = dim == 0 ? 4 : 7;
                        const auto        n_phys =
                          reader.count(e[p], "physical tag count");
                        if (e.size() < p + 1 + n_phys + (dim == 0 ? 0 : 1))
                          reader.fail("entity " + e[0] +
                                      " has fewer fields than its counts say");
                        if (dim == cell_dim && n_phys == 0)
                          unnamed_surfaces.insert(
                            reader.tag(e[0], "entity tag"));
                        if (dim == cell_dim && n_phys > 0)
                          ++n_named_surfaces;
                      }
                  }
                reader.end_of("Entities");
                // Gmsh saves only the cells of physical groups once there
                // are any: the cells of other surfaces would vanish.
                if (n_named_surfaces > 0 && !unnamed_surfaces.empty())
                  reader.fail(
                    std::string(cell_dim == 2 ? "surface " : "volume ") +
                    std::to_string(*std::min_element(unnamed_surfaces.begin(),
                                                     unnamed_surfaces.end())) +
                    " has no physical group, so its cells would be "
                    "dropped (give every " +
                    (cell_dim == 2 ? "surface a Physical Surface)"
                                   : "volume a Physical Volume)"));
                have_entities = true;
              }
            else if (t[0] == "$Nodes")
              {
                t = reader.expect(4, 4, "'numEntityBlocks numNodes ...'");
                reader.tag(t[2], "smallest node tag");
                reader.tag(t[3], "largest node tag");
                const auto n_blocks = reader.count(t[0], "block count");
                const auto n_total  = reader.count(t[1], "node count");
                reader.check_fits(n_total);
                nodes.expect(n_total);
                unsigned long long n_read = 0;
                for (unsigned long long b = 0; b < n_blocks; ++b)
                  {
                    t            = reader.expect(4, 4, "a node block header");
                    const auto n = reader.count(t[3], "node count of a block");
                    const bool parametric = t[2] != "0";
                    for (unsigned long long i = 0; i < n; ++i)
                      reader.add_node(nodes,
                                      reader.expect(1, 1, "a node tag")[0]);
                    for (unsigned long long i = 0; i < n; ++i)
                      {
                        t = reader.expect(3,
                                          parametric ? 6 : 3,
                                          "node coordinates 'x y z'");
                        for (const auto &x : t)
                          reader.coordinate(x);
                      }
                    n_read += n;
                  }
                if (n_read != n_total)
                  reader.fail("the node blocks hold " + std::to_string(n_read) +
                              " nodes, the header says " +
                              std::to_string(n_total));
                reader.end_of("Nodes");
                have_nodes = true;
              }
            else if (t[0] == "$Elements")
              {
                if (!have_nodes)
                  reader.fail("$Elements before $Nodes");
                t = reader.expect(4, 4, "'numEntityBlocks numElements ...'");
                reader.tag(t[2], "smallest element tag");
                reader.tag(t[3], "largest element tag");
                const auto n_blocks = reader.count(t[0], "block count");
                for (unsigned long long b = 0; b < n_blocks; ++b)
                  {
                    t = reader.expect(4, 4, "an element block header");
                    const long long    type = reader.tag(t[2], "element type");
                    const unsigned int n_v =
                      nodes_and_dimension(type, reader).first;
                    kinds.add(type, reader);
                    const auto n =
                      reader.count(t[3], "element count of a block");
                    if (t[0] == std::to_string(cell_dim) &&
                        unnamed_surfaces.count(reader.tag(t[1], "entity tag")))
                      reader.fail(
                        std::string(cell_dim == 2 ? "surface " : "volume ") +
                        t[1] +
                        " has no physical group, so its cells have "
                        "no material id (give every " +
                        (cell_dim == 2 ? "surface a Physical Surface)"
                                       : "volume a Physical Volume)"));
                    for (unsigned long long i = 0; i < n; ++i)
                      {
                        t = reader.expect(1 + n_v,
                                          1 + n_v,
                                          "an element 'tag nodes...'");
                        reader.tag(t[0], "element tag");
                        reader.check_element_nodes(nodes, t, 1);
                      }
                  }
                reader.end_of("Elements");
                have_elements = true;
              }
            else if (t[0].size() > 1 && t[0][0] == '$')
              reader.skip_section(t[0].substr(1));
          }
        if (!have_entities || !have_nodes || !have_elements)
          reader.fail("no $Entities, $Nodes or $Elements section "
                      "(truncated?)");
        return kinds.dimension;
      }
    } // namespace



    std::pair<unsigned int, unsigned int>
    element_kind(const long long type)
    {
      switch (type)
        {
          case 15:
            return {1, 0};
          case 1:
            return {2, 1};
          case 2:
            return {3, 2};
          case 3:
            return {4, 2};
          case 4:
            return {4, 3};
          case 5:
            return {8, 3};
          default:
            return {0, 0};
        }
    }



    unsigned int
    check_msh(const std::string &file)
    {
      MshReader                reader(file);
      std::vector<std::string> t;
      if (!reader.next(t) || t.size() != 1 || t[0] != "$MeshFormat")
        reader.fail("not a Gmsh .msh file (no $MeshFormat on line 1)");
      t = reader.expect(3, 3, "'version file-type data-size'");
      if (t[1] != "0")
        reader.fail("binary .msh files are not supported; save as ASCII "
                    "(Mesh.Binary = 0)");
      const std::string version = t[0];
      reader.end_of("MeshFormat");
      if (version != "2.2" && version != "2" && version != "4.1")
        reader.fail("format version " + version +
                    " is not supported (2.2 or 4.1)");
      const unsigned int dim =
        version == "4.1" ? check_msh4(reader) : check_msh2(reader);
      if (dim < 2)
        reader.fail("the mesh has no cells (no triangles, quadrilaterals, "
                    "tetrahedra or hexahedra)");
      return dim;
    }
  } // namespace gmsh_input
} // namespace knee_contact
