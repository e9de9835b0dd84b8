#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <cmath>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    Description<2>
    read_ucd(const std::string &file)
    {
      Lines       lines(file);
      std::string line;
      // The next line that is not a comment, split at white space.
      const auto next = [&](const std::string &what) {
        while (lines.next(line))
          {
            const std::string text = trim(line);
            if (text.empty() || text[0] == '#')
              continue;
            return words(text);
          }
        lines.fail("the file ends where " + what + " should be");
      };
      const auto count = [&](const std::string &text, const std::string &what) {
        const long long n = to_integer(text, lines);
        if (n < 0 || static_cast<std::uintmax_t>(n) > lines.size)
          lines.fail(what + " " + text + " is more than the file's " +
                     std::to_string(lines.size) + " bytes can hold");
        return static_cast<std::size_t>(n);
      };

      auto header = next("the counts line");
      if (header.size() != 5)
        lines.fail("expected 'nodes cells node-data cell-data model-data', "
                   "found " +
                   std::to_string(header.size()) + " numbers");
      const std::size_t n_nodes = count(header[0], "node count"),
                        n_cells = count(header[1], "cell count");

      Description<2>                    mesh;
      std::map<long long, unsigned int> vertex_of_node;
      for (std::size_t i = 0; i < n_nodes; ++i)
        {
          const auto words = next("a node");
          if (words.size() != 4)
            lines.fail("a node needs 'number x y z' (found " +
                       std::to_string(words.size()) + " fields)");
          if (to_number(words[3], lines) != 0)
            lines.fail("node " + words[0] +
                       " has z != 0: knee_contact meshes lie in the x-y "
                       "plane");
          if (!vertex_of_node
                 .emplace(to_integer(words[0], lines), mesh.vertices.size())
                 .second)
            lines.fail("node " + words[0] + " appears twice");
          mesh.vertices.emplace_back(to_number(words[1], lines),
                                     to_number(words[2], lines));
        }
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const auto words = next("a cell");
          if (words.size() < 3)
            lines.fail("a cell needs 'number material type vertices'");
          const long long   id   = to_integer(words[1], lines);
          const std::string type = words[2];
          const std::map<std::string, std::size_t> n_vertices = {{"pt", 1},
                                                                 {"line", 2},
                                                                 {"tri", 3},
                                                                 {"quad", 4}};
          if (n_vertices.count(type) == 0)
            lines.fail("cell type '" + type +
                       "' is not pt, line, tri or quad; knee_contact reads "
                       "linear 2D cells");
          if (words.size() != 3 + n_vertices.at(type))
            lines.fail("a " + type + " needs " +
                       std::to_string(n_vertices.at(type)) + " vertices");
          if (id < 0 || id >= 255)
            lines.fail((type == "line" ? "boundary id " : "material id ") +
                       words[1] + " is not in 0..254");
          std::vector<unsigned int> vertices;
          for (std::size_t k = 3; k < words.size(); ++k)
            {
              const auto it = vertex_of_node.find(to_integer(words[k], lines));
              if (it == vertex_of_node.end())
                lines.fail("cell " + words[0] + " refers to node " + words[k] +
                           ", which is not given");
              vertices.push_back(it->second);
            }
          if (std::set<unsigned int>(vertices.begin(), vertices.end()).size() !=
              vertices.size())
            lines.fail("cell " + words[0] + " names a node twice");
          if (type == "line")
            add_boundary_line(mesh, vertices[0], vertices[1], id);
          else if (type != "pt")
            add_cell(mesh, vertices, id);
        }
      AssertThrow(!mesh.cells.empty(),
                  ExcMessage("Mesh/File: '" + file +
                             "' has no tri or quad cells"));
      GridTools::delete_unused_vertices(mesh.vertices,
                                        mesh.cells,
                                        mesh.subcells);
      return mesh;
    }
  } // namespace mesh_readers
} // namespace knee_contact
