#include <knee_contact/core/input.h>
#include <knee_contact/mesh/mesh_readers.h>

#include <deal.II/grid/grid_tools.h>

#include <boost/property_tree/ptree.hpp>
#include <boost/property_tree/xml_parser.hpp>
#include <zlib.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

namespace knee_contact
{
  namespace mesh_readers
  {
    namespace
    {
      /**
       * A text file read line by line, with errors that name file and line.
       */
      class Lines
      {
      public:
        explicit Lines(const std::string &file)
          : file(file)
          , in(file)
        {
          AssertThrow(in.good(),
                      ExcMessage("Mesh/File: cannot open '" + file + "'"));
          size = std::filesystem::file_size(file);
        }

        bool
        next(std::string &line)
        {
          if (pending)
            {
              line    = held;
              pending = false;
              return true;
            }
          if (!std::getline(in, line))
            return false;
          ++number;
          if (!line.empty() && line.back() == '\r')
            line.pop_back();
          return true;
        }

        /** Give @p line back: the next call of next() returns it again. */
        void
        put_back(const std::string &line)
        {
          held    = line;
          pending = true;
        }

        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(
            input::cap("Mesh/File: '" + file + "' line " +
                       std::to_string(number) + ": " + what));
        }

        const std::string file;
        std::uintmax_t    size   = 0;
        unsigned long     number = 0;

      private:
        std::ifstream in;
        std::string   held;
        bool          pending = false;
      };

      std::string
      upper(std::string text)
      {
        for (char &c : text)
          c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
        return text;
      }

      std::string
      trim(const std::string &text)
      {
        const auto first = text.find_first_not_of(" \t");
        if (first == std::string::npos)
          return "";
        return text.substr(first, text.find_last_not_of(" \t") - first + 1);
      }

      std::vector<std::string>
      fields(const std::string &line)
      {
        std::vector<std::string> result;
        std::stringstream        stream(line);
        std::string              field;
        while (std::getline(stream, field, ','))
          result.push_back(trim(field));
        // "1, 2," has no third field.
        if (!result.empty() && result.back().empty())
          result.pop_back();
        return result;
      }

      long long
      to_integer(const std::string &text, const Lines &lines)
      {
        std::size_t end   = 0;
        long long   value = 0;
        try
          {
            value = std::stoll(text, &end);
          }
        catch (...)
          {
            end = 0;
          }
        if (end == 0 || end != text.size())
          lines.fail("'" + text + "' is not an integer");
        return value;
      }

      double
      to_number(const std::string &text, const Lines &lines)
      {
        std::size_t end   = 0;
        double      value = 0;
        try
          {
            value = std::stod(text, &end);
          }
        catch (...)
          {
            end = 0;
          }
        if (end == 0 || end != text.size() || !std::isfinite(value))
          lines.fail("'" + text + "' is not a finite number");
        return value;
      }

      /**
       * The value of "KEY=value" among the options of a keyword line, upper
       * case, or "" if absent.
       */
      std::string
      option(const std::vector<std::string> &keyword_fields,
             const std::string              &key)
      {
        for (std::size_t i = 1; i < keyword_fields.size(); ++i)
          {
            const auto equal = keyword_fields[i].find('=');
            if (equal != std::string::npos &&
                upper(trim(keyword_fields[i].substr(0, equal))) == key)
              return upper(trim(keyword_fields[i].substr(equal + 1)));
          }
        return "";
      }

      bool
      has_flag(const std::vector<std::string> &keyword_fields,
               const std::string              &flag)
      {
        for (std::size_t i = 1; i < keyword_fields.size(); ++i)
          if (upper(keyword_fields[i]) == flag)
            return true;
        return false;
      }

      /**
       * Abaqus' face k of a 2D element joins its nodes k and k+1 (the last
       * back to the first).
       */
      std::pair<long long, long long>
      face_nodes(const std::vector<long long> &nodes, const unsigned int k)
      {
        return {nodes[k], nodes[(k + 1) % nodes.size()]};
      }

      /**
       * Add a triangle or quadrilateral whose @p vertices run round it, as
       * Abaqus, UCD and VTK list them; deal.II's order is lexicographic
       * (0 1 3 2 round a quadrilateral).
       */
      void
      add_cell(Description<2>              &mesh,
               std::vector<unsigned int> vertices,
               const types::material_id  material_id)
      {
        if (vertices.size() == 4)
          std::swap(vertices[2], vertices[3]);
        CellData<2> cell(vertices.size());
        cell.vertices    = vertices;
        cell.material_id = material_id;
        mesh.cells.push_back(cell);
      }

      void
      add_boundary_line(Description<2>             &mesh,
                        const unsigned int       a,
                        const unsigned int       b,
                        const types::boundary_id boundary_id)
      {
        CellData<1> line;
        line.vertices    = {a, b};
        line.boundary_id = boundary_id;
        mesh.subcells.boundary_lines.push_back(line);
      }
    } // namespace



    Description<2>
    read_abaqus(const std::string                         &file,
                const std::map<std::string, unsigned int> &element_sets,
                const std::map<std::string, unsigned int> &boundary_sets)
    {
      Lines lines(file);
      // Element numbers and node numbers as the deck gives them.
      std::map<long long, Point<2>>               nodes;
      std::map<long long, std::vector<long long>> elements;
      // Two-node line elements (trusses, beams): Gmsh's .inp export writes
      // the physical curves as these; a set of them names boundary edges.
      std::map<long long, std::pair<long long, long long>> line_elements;
      std::map<std::string, std::set<long long>>           elsets, nsets;
      std::map<std::string, std::vector<std::pair<std::string, unsigned int>>>
                               surfaces;      // (element or elset, face)
      std::set<std::string>    node_surfaces; // TYPE=NODE: named as node sets
      std::vector<std::string> sections;      // element sets, in file order
      // At most one number per byte of the file: counts beyond that are not
      // a mesh but an attack on memory.
      const std::uintmax_t limit = lines.size;

      std::string  line;
      std::string  block; // the keyword whose data lines follow
      std::string  block_set;
      bool         generate        = false;
      unsigned int n_element_nodes = 0;
      while (lines.next(line))
        {
          const std::string text = trim(line);
          if (text.empty() || text.rfind("**", 0) == 0)
            continue;
          if (text[0] == '*')
            {
              const auto        keyword_fields = fields(text);
              const std::string keyword        = upper(keyword_fields[0]);
              block                            = "";
              generate = has_flag(keyword_fields, "GENERATE");
              if (keyword == "*NODE")
                {
                  block     = keyword;
                  block_set = option(keyword_fields, "NSET");
                }
              else if (keyword == "*ELEMENT")
                {
                  const std::string type = option(keyword_fields, "TYPE");
                  const bool        plane =
                    type.rfind("CPS", 0) == 0 || type.rfind("CPE", 0) == 0;
                  const char n = type.size() > 3 ? type[3] : ' ';
                  const std::set<std::string> line_types = {"T2D2",
                                                            "T3D2",
                                                            "T2D2H",
                                                            "T3D2H",
                                                            "B21",
                                                            "B31",
                                                            "B21H",
                                                            "B31H"};
                  if (line_types.count(type) != 0)
                    n_element_nodes = 2;
                  else if (!plane || (n != '3' && n != '4') ||
                           type.find_first_not_of("RHI", 4) !=
                             std::string::npos)
                    lines.fail(
                      "element type '" + type +
                      "' is not a linear plane element (knee_contact reads "
                      "CPS3, CPE3, CPS4, CPE4 and their R, H, I variants, "
                      "and two-node lines T2D2, T3D2, B21, B31 as boundary "
                      "edges)");
                  else
                    n_element_nodes = n - '0';
                  block     = keyword;
                  block_set = option(keyword_fields, "ELSET");
                }
              else if (keyword == "*ELSET" || keyword == "*NSET")
                {
                  block     = keyword;
                  block_set = option(keyword_fields,
                                     keyword == "*ELSET" ? "ELSET" : "NSET");
                  if (block_set.empty())
                    lines.fail(keyword + " without a name");
                  (keyword == "*ELSET" ? elsets : nsets)[block_set];
                }
              else if (keyword == "*SURFACE")
                {
                  block_set = option(keyword_fields, "NAME");
                  if (block_set.empty())
                    lines.fail("*Surface without a name");
                  const std::string type = option(keyword_fields, "TYPE");
                  if (type == "NODE")
                    {
                      block = "*NSET";
                      nsets[block_set];
                      node_surfaces.insert(block_set);
                    }
                  else if (type.empty() || type == "ELEMENT")
                    {
                      block = keyword;
                      surfaces[block_set];
                    }
                  else
                    lines.fail("*Surface type '" + type +
                               "' (knee_contact reads ELEMENT and NODE)");
                }
              else if (keyword == "*SOLID SECTION")
                {
                  const std::string set = option(keyword_fields, "ELSET");
                  if (set.empty())
                    lines.fail("*Solid Section without ELSET");
                  sections.push_back(set);
                }
              else if (keyword == "*PART" && !nodes.empty())
                lines.fail("a second *Part: knee_contact reads one part "
                           "(export the model flat, without parts and "
                           "instances)");
              else if (keyword == "*INSTANCE")
                {
                  // An instance may move its part: read it only if it does
                  // not (the next line ends it).
                  std::string next;
                  if (lines.next(next) && upper(trim(next)) != "*END INSTANCE")
                    lines.fail("an *Instance that moves its part: knee_contact "
                               "reads parts in place (export the model flat)");
                }
              // Every other keyword (materials, steps, loads, ...) and its
              // data is not mesh: skipped.
              continue;
            }

          const auto values = fields(text);
          if (block == "*NODE")
            {
              if (values.size() < 3 || values.size() > 4)
                lines.fail("a node needs 'number, x, y' (found " +
                           std::to_string(values.size()) + " fields)");
              const long long id = to_integer(values[0], lines);
              const Point<2>  p(to_number(values[1], lines),
                               to_number(values[2], lines));
              if (values.size() == 4 && to_number(values[3], lines) != 0)
                lines.fail("node " + values[0] +
                           " has z != 0: knee_contact meshes lie in the "
                           "x-y plane");
              if (!nodes.emplace(id, p).second)
                lines.fail("node " + values[0] + " appears twice");
              if (nodes.size() > limit)
                lines.fail("more nodes than the file can hold");
              if (!block_set.empty())
                nsets[block_set].insert(id);
            }
          else if (block == "*ELEMENT")
            {
              if (values.size() != n_element_nodes + 1)
                lines.fail("element needs its number and " +
                           std::to_string(n_element_nodes) +
                           " node numbers on one line (found " +
                           std::to_string(values.size()) + " fields)");
              const long long        id = to_integer(values[0], lines);
              std::vector<long long> element;
              for (unsigned int k = 1; k < values.size(); ++k)
                {
                  element.push_back(to_integer(values[k], lines));
                  if (nodes.count(element.back()) == 0)
                    lines.fail("element " + values[0] + " refers to node " +
                               values[k] + ", which no *Node line gives");
                }
              if (std::set<long long>(element.begin(), element.end()).size() !=
                  element.size())
                lines.fail("element " + values[0] + " names a node twice");
              if (elements.count(id) != 0 || line_elements.count(id) != 0)
                lines.fail("element " + values[0] + " appears twice");
              if (element.size() == 2)
                line_elements.emplace(id, std::minmax(element[0], element[1]));
              else
                elements.emplace(id, element);
              if (!block_set.empty())
                elsets[block_set].insert(id);
            }
          else if (block == "*ELSET" || block == "*NSET")
            {
              auto &set = (block == "*ELSET" ? elsets : nsets)[block_set];
              if (generate)
                {
                  if (values.size() < 2 || values.size() > 3)
                    lines.fail("GENERATE needs 'first, last[, step]'");
                  const long long first = to_integer(values[0], lines),
                                  last  = to_integer(values[1], lines),
                                  step  = values.size() == 3
                                            ? to_integer(values[2], lines)
                                            : 1;
                  if (step <= 0 || last < first ||
                      (last - first) / step > static_cast<long long>(limit))
                    lines.fail("GENERATE range '" + text +
                               "' is empty or too long");
                  for (long long i = first; i <= last; i += step)
                    set.insert(i);
                }
              else
                for (const auto &value : values)
                  {
                    if (!value.empty() &&
                        !std::isdigit(static_cast<unsigned char>(value[0])))
                      {
                        // A set made of other sets.
                        const auto &sets = block == "*ELSET" ? elsets : nsets;
                        const auto  it   = sets.find(upper(value));
                        if (it == sets.end())
                          lines.fail("set '" + value +
                                     "' is not defined above");
                        set.insert(it->second.begin(), it->second.end());
                      }
                    else
                      set.insert(to_integer(value, lines));
                  }
            }
          else if (block == "*SURFACE")
            {
              if (values.size() != 2 || values[1].size() != 2 ||
                  std::toupper(values[1][0]) != 'S' || values[1][1] < '1' ||
                  values[1][1] > '4')
                lines.fail("a surface line needs 'element or element set, "
                           "S1..S4'");
              surfaces[block_set].emplace_back(upper(values[0]),
                                               values[1][1] - '1');
            }
        }
      AssertThrow(!elements.empty(),
                  ExcMessage("Mesh/File: '" + file +
                             "' has no *Element lines with plane elements"));

      // Material ids.
      std::map<std::string, unsigned int> material_of_set = element_sets;
      if (material_of_set.empty())
        for (unsigned int i = 0; i < sections.size(); ++i)
          material_of_set.emplace(upper(sections[i]), i + 1);
      std::map<long long, unsigned int> material;
      for (const auto &[name, id] : material_of_set)
        {
          const auto set = elsets.find(upper(name));
          AssertThrow(set != elsets.end(),
                      ExcMessage("Mesh/Abaqus element sets: '" + file +
                                 "' has no element set '" + name + "'"));
          for (const long long e : set->second)
            {
              if (line_elements.count(e) != 0)
                continue; // boundary edges, not cells
              AssertThrow(elements.count(e) != 0,
                          ExcMessage("Mesh/File: '" + file +
                                     "': element set '" + name +
                                     "' names element " + std::to_string(e) +
                                     ", which no *Element line gives"));
              const auto [it, fresh] = material.emplace(e, id);
              AssertThrow(fresh || it->second == id,
                          ExcMessage("Mesh/Abaqus element sets: element " +
                                     std::to_string(e) + " of '" + file +
                                     "' is in two sets with different "
                                     "material ids"));
            }
        }
      for (const auto &element : elements)
        AssertThrow(material.count(element.first) != 0,
                    ExcMessage("Mesh/Abaqus element sets: element " +
                               std::to_string(element.first) + " of '" + file +
                               "' is in no set given a material id (" +
                               (element_sets.empty()
                                  ? "no *Solid Section names it"
                                  : "name its set in the scene") +
                               ")"));

      Description<2>                       mesh;
      std::map<long long, unsigned int> vertex_of_node;
      for (const auto &[id, p] : nodes)
        {
          vertex_of_node[id] = mesh.vertices.size();
          mesh.vertices.push_back(p);
        }
      for (const auto &[id, element] : elements)
        {
          std::vector<unsigned int> vertices;
          for (const long long node : element)
            vertices.push_back(vertex_of_node[node]);
          add_cell(mesh, vertices, material[id]);
        }

      // Boundary ids: element faces of surfaces, or edges with both nodes
      // in a node set; only faces on the boundary (one element) count.
      std::map<std::pair<long long, long long>, unsigned int>
        n_elements_of_edge;
      for (const auto &[id, element] : elements)
        for (unsigned int k = 0; k < element.size(); ++k)
          {
            auto e = face_nodes(element, k);
            ++n_elements_of_edge[std::minmax(e.first, e.second)];
          }
      std::map<std::pair<long long, long long>, unsigned int> boundary_id;
      for (const auto &[name, id] : boundary_sets)
        {
          const std::string key    = upper(name);
          const auto        before = boundary_id.size();
          if (surfaces.count(key) != 0)
            for (const auto &[owner, face] : surfaces[key])
              {
                std::set<long long> owners;
                if (std::isdigit(static_cast<unsigned char>(owner[0])))
                  owners.insert(std::stoll(owner));
                else
                  {
                    AssertThrow(elsets.count(owner) != 0,
                                ExcMessage("Mesh/File: '" + file +
                                           "': surface '" + name +
                                           "' names element set '" + owner +
                                           "', which is not defined"));
                    owners = elsets[owner];
                  }
                for (const long long e : owners)
                  {
                    const auto element = elements.find(e);
                    AssertThrow(
                      element != elements.end() &&
                        face < element->second.size(),
                      ExcMessage("Mesh/File: '" + file + "': surface '" + name +
                                 "' names face S" + std::to_string(face + 1) +
                                 " of element " + std::to_string(e) +
                                 ", which has no such face"));
                    const auto edge = face_nodes(element->second, face);
                    boundary_id[std::minmax(edge.first, edge.second)] = id;
                  }
              }
          else if (elsets.count(key) != 0 && !elsets[key].empty() &&
                   std::all_of(elsets[key].begin(),
                               elsets[key].end(),
                               [&](const long long e) {
                                 return line_elements.count(e) != 0;
                               }))
            for (const long long e : elsets[key])
              boundary_id[line_elements[e]] = id;
          else if (nsets.count(key) != 0)
            {
              const auto &set = nsets[key];
              for (const auto &[edge, n] : n_elements_of_edge)
                if (n == 1 && set.count(edge.first) && set.count(edge.second))
                  boundary_id[edge] = id;
            }
          else
            AssertThrow(false,
                        ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                   "' has no surface, node set or set of "
                                   "line elements '" +
                                   name + "'"));
          AssertThrow(boundary_id.size() > before,
                      ExcMessage("Mesh/Abaqus boundary sets: surface or node "
                                 "set '" +
                                 name + "' of '" + file +
                                 "' has no edge on the boundary"));
        }
      for (const auto &[edge, id] : boundary_id)
        {
          AssertThrow(n_elements_of_edge.count(edge) != 0,
                      ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                 "': the line from node " +
                                 std::to_string(edge.first) + " to node " +
                                 std::to_string(edge.second) +
                                 " of boundary id " + std::to_string(id) +
                                 " is no edge of a plane element"));
          AssertThrow(n_elements_of_edge[edge] == 1,
                      ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                 "': the edge from node " +
                                 std::to_string(edge.first) + " to node " +
                                 std::to_string(edge.second) +
                                 " of boundary id " + std::to_string(id) +
                                 " lies between two elements"));
          add_boundary_line(mesh,
                            vertex_of_node[edge.first],
                            vertex_of_node[edge.second],
                            id);
        }
      GridTools::delete_unused_vertices(mesh.vertices,
                                        mesh.cells,
                                        mesh.subcells);
      return mesh;
    }



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
            std::vector<std::string> words;
            std::stringstream        stream(text);
            std::string              word;
            while (stream >> word)
              words.push_back(word);
            return words;
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

      Description<2>                       mesh;
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



    namespace
    {
      /**
       * Decoding of the DataArrays of a VTK XML file: base64 and zlib blocks
       * as VTK writes them (header of UInt32 or UInt64 byte counts).
       */
      class VtuArrays
      {
      public:
        VtuArrays(const std::string &file,
                  const bool         header_64,
                  const bool         compressed,
                  std::string        appended)
          : file(file)
          , header_64(header_64)
          , compressed(compressed)
          , appended(std::move(appended))
        {}

        /**
         * The @p n values of @p array (a DataArray element) as doubles.
         */
        std::vector<double>
        values(const boost::property_tree::ptree &array,
               const std::size_t                  n) const
        {
          const std::string name   = array.get("<xmlattr>.Name", "");
          const std::string type   = array.get("<xmlattr>.type", "");
          const std::string format = array.get("<xmlattr>.format", "");
          const std::map<std::string, unsigned int> sizes = {{"Int8", 1},
                                                             {"UInt8", 1},
                                                             {"Int16", 2},
                                                             {"UInt16", 2},
                                                             {"Int32", 4},
                                                             {"UInt32", 4},
                                                             {"Int64", 8},
                                                             {"UInt64", 8},
                                                             {"Float32", 4},
                                                             {"Float64", 8}};
          if (sizes.count(type) == 0)
            fail("DataArray '" + name + "' has type '" + type + "'");
          std::vector<double> result;
          if (format == "ascii")
            {
              std::stringstream stream(array.data());
              std::string       word;
              while (stream >> word && result.size() <= n)
                {
                  std::size_t end   = 0;
                  double      value = 0;
                  try
                    {
                      value = std::stod(word, &end);
                    }
                  catch (...)
                    {
                      end = 0;
                    }
                  if (end != word.size() || !std::isfinite(value))
                    fail("DataArray '" + name + "': '" + word +
                         "' is not a finite number");
                  result.push_back(value);
                }
            }
          else
            {
              std::string       bytes;
              const std::size_t expected = n * sizes.at(type);
              if (format == "binary")
                bytes = decode(trim_all(array.data()), name, expected);
              else if (format == "appended")
                {
                  const std::string offset_text =
                    array.get("<xmlattr>.offset", "");
                  std::size_t offset = 0;
                  try
                    {
                      offset = std::stoull(offset_text);
                    }
                  catch (...)
                    {
                      fail("DataArray '" + name + "' has no valid offset");
                    }
                  if (offset >= appended.size())
                    fail("DataArray '" + name + "': offset " + offset_text +
                         " is beyond the appended data");
                  bytes = unpack(appended.substr(offset), name, expected);
                }
              else
                fail("DataArray '" + name + "' has format '" + format +
                     "' (ascii, binary or appended)");
              const unsigned int size = sizes.at(type);
              if (bytes.size() < n * size)
                fail("DataArray '" + name + "' holds " +
                     std::to_string(bytes.size() / size) + " values, " +
                     std::to_string(n) + " expected");
              for (std::size_t i = 0; i < n; ++i)
                result.push_back(number(bytes.data() + i * size, type));
            }
          if (result.size() != n)
            fail("DataArray '" + name + "' holds " +
                 std::to_string(result.size()) + " values, " +
                 std::to_string(n) + " expected");
          return result;
        }

      private:
        [[noreturn]] void
        fail(const std::string &what) const
        {
          throw std::runtime_error(
            input::cap("Mesh/File: '" + file + "': " + what));
        }

        static std::string
        trim_all(const std::string &text)
        {
          std::string result;
          for (const char c : text)
            if (!std::isspace(static_cast<unsigned char>(c)))
              result += c;
          return result;
        }

        std::string
        base64(const std::string &text, const std::string &name) const
        {
          static const std::string alphabet =
            "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
          std::string  result;
          unsigned int buffer = 0, bits = 0;
          for (const char c : text)
            {
              if (c == '=')
                break;
              const auto k = alphabet.find(c);
              if (k == std::string::npos)
                fail("DataArray '" + name + "' is not base64");
              buffer = (buffer << 6) | k;
              bits += 6;
              if (bits >= 8)
                {
                  bits -= 8;
                  result += static_cast<char>((buffer >> bits) & 0xff);
                }
            }
          return result;
        }

        std::uint64_t
        header_item(const std::string &bytes, const std::size_t i) const
        {
          const std::size_t size = header_64 ? 8 : 4;
          if (bytes.size() < (i + 1) * size)
            fail("a DataArray's header is cut off");
          std::uint64_t value = 0;
          for (std::size_t b = 0; b < size; ++b)
            value |=
              std::uint64_t(static_cast<unsigned char>(bytes[i * size + b]))
              << (8 * b);
          return value;
        }

        /** Inline binary: base64, the header apart if compressed. */
        std::string
        decode(const std::string &text,
               const std::string &name,
               const std::size_t  expected) const
        {
          const std::size_t size       = header_64 ? 8 : 4;
          const auto        b64_length = [](const std::size_t bytes) {
            return 4 * ((bytes + 2) / 3);
          };
          if (!compressed)
            {
              // VTK encodes the header and the data as two base64 streams
              // (the header's ends in '='); other writers as one.
              const std::size_t header_length = b64_length(size);
              if (text.size() >= header_length &&
                  text[header_length - 1] == '=')
                return unpack(base64(text.substr(0, header_length), name) +
                                base64(text.substr(header_length), name),
                              name,
                              expected);
              return unpack(base64(text, name), name, expected);
            }
          const std::string first =
            base64(text.substr(0, b64_length(3 * size)), name);
          const std::uint64_t n_blocks = header_item(first, 0);
          if (n_blocks > text.size())
            fail("DataArray '" + name + "': block count " +
                 std::to_string(n_blocks) + " is more than it can hold");
          const std::size_t header_length = b64_length((3 + n_blocks) * size);
          if (header_length > text.size())
            fail("DataArray '" + name + "' is cut off");
          return unpack(base64(text.substr(0, header_length), name) +
                          base64(text.substr(header_length), name),
                        name,
                        expected,
                        (3 + n_blocks) * size);
        }

        /**
         * Header and data (raw bytes): the data, inflated if compressed.
         * @p expected: the bytes the array must hold (compressed data must
         * say exactly that before anything is inflated, so that a header
         * cannot ask for memory the file does not justify).
         * @p header_bytes: the length of a header padded by base64.
         */
        std::string
        unpack(const std::string &bytes,
               const std::string &name,
               const std::size_t  expected,
               std::size_t        header_bytes = 0) const
        {
          const std::size_t size = header_64 ? 8 : 4;
          if (!compressed)
            {
              const std::uint64_t n = header_item(bytes, 0);
              if (n > bytes.size() - size)
                fail("DataArray '" + name + "' says " + std::to_string(n) +
                     " bytes, holds " + std::to_string(bytes.size() - size));
              return bytes.substr(size, n);
            }
          const std::uint64_t n_blocks = header_item(bytes, 0),
                              block    = header_item(bytes, 1),
                              last     = header_item(bytes, 2);
          if (n_blocks > bytes.size() || block > (std::uint64_t(1) << 31) ||
              last > block)
            fail("DataArray '" + name + "' has an impossible header");
          const std::uint64_t declared =
            n_blocks == 0 ? 0
                          : (n_blocks - 1) * block + (last != 0 ? last : block);
          if (declared != expected)
            fail("DataArray '" + name + "' holds " + std::to_string(declared) +
                 " bytes, " + std::to_string(expected) + " expected");
          std::size_t at =
            std::max<std::size_t>(header_bytes, (3 + n_blocks) * size);
          if (at > bytes.size())
            fail("DataArray '" + name + "' is cut off");
          std::string result;
          for (std::uint64_t b = 0; b < n_blocks; ++b)
            {
              const std::uint64_t length = header_item(bytes, 3 + b);
              if (length > bytes.size() - at)
                fail("DataArray '" + name + "' is cut off");
              uLongf inflated = (b + 1 == n_blocks && last != 0) ? last : block;
              std::string out(inflated, '\0');
              if (uncompress(reinterpret_cast<Bytef *>(out.data()),
                             &inflated,
                             reinterpret_cast<const Bytef *>(bytes.data() + at),
                             length) != Z_OK)
                fail("DataArray '" + name +
                     "': a zlib block does not "
                     "inflate");
              result += out.substr(0, inflated);
              at += length;
            }
          return result;
        }

        static double
        number(const char *p, const std::string &type)
        {
          const auto get = [p](auto value) {
            std::memcpy(&value, p, sizeof(value));
            return static_cast<double>(value);
          };
          if (type == "Int8")
            return get(std::int8_t());
          if (type == "UInt8")
            return get(std::uint8_t());
          if (type == "Int16")
            return get(std::int16_t());
          if (type == "UInt16")
            return get(std::uint16_t());
          if (type == "Int32")
            return get(std::int32_t());
          if (type == "UInt32")
            return get(std::uint32_t());
          if (type == "Int64")
            return get(std::int64_t());
          if (type == "UInt64")
            return get(std::uint64_t());
          if (type == "Float32")
            return get(float());
          return get(double());
        }

        const std::string file;
        const bool        header_64;
        const bool        compressed;
        const std::string appended;
      };
    } // namespace



    Description<2>
    read_vtu(const std::string &file)
    {
      const std::uintmax_t size = std::filesystem::file_size(file);
      std::ifstream        in(file, std::ios::binary);
      std::string          text(size, '\0');
      in.read(text.data(), size);
      AssertThrow(in.good() || in.eof(),
                  ExcMessage("Mesh/File: cannot read '" + file + "'"));
      const auto fail = [&file](const std::string &what) {
        throw std::runtime_error(
          input::cap("Mesh/File: '" + file + "': " + what));
      };
      // A number read from a file as it would be written there.
      const auto text_of = [](const double value) {
        std::ostringstream stream;
        stream << value;
        return stream.str();
      };

      // Raw appended data is not XML: cut it off before parsing.
      std::string appended;
      const auto  appended_at = text.find("<AppendedData");
      if (appended_at != std::string::npos)
        {
          const auto tag_end = text.find('>', appended_at);
          const auto start   = text.find('_', tag_end);
          const auto end     = text.rfind("</AppendedData>");
          if (tag_end == std::string::npos || start == std::string::npos ||
              end == std::string::npos || end < start)
            fail("the AppendedData section is cut off");
          if (text.substr(appended_at, tag_end - appended_at).find("\"raw\"") ==
              std::string::npos)
            fail("appended data that is not raw (write it raw, or as "
                 "ascii or binary DataArrays)");
          appended = text.substr(start + 1, end - start - 1);
          text     = text.substr(0, appended_at) + "</VTKFile>";
        }
      boost::property_tree::ptree tree;
      try
        {
          std::stringstream stream(text);
          boost::property_tree::read_xml(stream, tree);
        }
      catch (const boost::property_tree::xml_parser_error &exc)
        {
          fail("line " + std::to_string(exc.line()) + ": " + exc.message() +
               " (not a VTK XML file?)");
        }
      const auto root = tree.get_child_optional("VTKFile");
      if (!root)
        fail("no VTKFile element");
      if (root->get("<xmlattr>.type", "") != "UnstructuredGrid")
        fail("VTKFile type is '" + root->get("<xmlattr>.type", "") +
             "'; knee_contact reads UnstructuredGrid");
      if (root->get("<xmlattr>.byte_order", "LittleEndian") != "LittleEndian")
        fail("big-endian data (write it little-endian)");
      const std::string header = root->get("<xmlattr>.header_type", "UInt32");
      if (header != "UInt32" && header != "UInt64")
        fail("header_type '" + header + "'");
      const std::string compressor = root->get("<xmlattr>.compressor", "");
      if (!compressor.empty() && compressor != "vtkZLibDataCompressor")
        fail("compressor '" + compressor +
             "' (knee_contact reads zlib and uncompressed data)");
      const auto pieces = root->get_child_optional("UnstructuredGrid");
      if (!pieces || pieces->count("Piece") != 1)
        fail("knee_contact reads an UnstructuredGrid of one Piece");
      const auto &piece = pieces->get_child("Piece");
      const auto  count = [&](const std::string &attribute) {
        const std::string text = piece.get("<xmlattr>." + attribute, "");
        std::size_t       n    = 0;
        try
          {
            n = std::stoull(text);
          }
        catch (...)
          {
            fail("Piece has no valid " + attribute);
          }
        if (n > size)
          fail(attribute + " " + text + " is more than the file's " +
               std::to_string(size) + " bytes can hold");
        return n;
      };
      const std::size_t n_points = count("NumberOfPoints"),
                        n_cells  = count("NumberOfCells");
      const VtuArrays arrays(file,
                             header == "UInt64",
                             !compressor.empty(),
                             std::move(appended));
      const auto      array = [&](const std::string &section,
                             const std::string &name,
                             const std::size_t  n,
                             const bool         required) {
        const auto parent = piece.get_child_optional(section);
        if (parent)
          for (const auto &[tag, child] : *parent)
            if (tag == "DataArray" &&
                (name.empty() || child.get("<xmlattr>.Name", "") == name))
              return arrays.values(child, n);
        if (required)
          fail("no DataArray '" + name + "' in " + section);
        return std::vector<double>();
      };

      const auto points      = array("Points", "", 3 * n_points, true);
      const auto offsets     = array("Cells", "offsets", n_cells, true);
      const auto types       = array("Cells", "types", n_cells, true);
      const auto n_connected = n_cells == 0 ? 0. : offsets.back();
      if (!(n_connected >= 0 && n_connected <= size))
        fail("the last offset is not a connectivity length");
      const auto connectivity =
        array("Cells", "connectivity", std::size_t(n_connected), true);
      const auto ids = array("CellData", "MaterialID", n_cells, false);

      Description<2> mesh;
      for (std::size_t i = 0; i < n_points; ++i)
        {
          for (unsigned int d = 0; d < 3; ++d)
            if (!std::isfinite(points[3 * i + d]))
              fail("point " + std::to_string(i) +
                   " has a coordinate that is not finite");
          if (points[3 * i + 2] != 0)
            fail("point " + std::to_string(i) +
                 " has z != 0: knee_contact meshes lie in the x-y plane");
          mesh.vertices.emplace_back(points[3 * i], points[3 * i + 1]);
        }
      double begin = 0;
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const double                        end        = offsets[c];
          const std::map<double, std::size_t> n_vertices = {{1, 1},
                                                            {3, 2},
                                                            {5, 3},
                                                            {9, 4}};
          if (types[c] != std::floor(types[c]) || end != std::floor(end))
            fail("cell " + std::to_string(c) +
                 ": a type or an offset that is not an integer");
          if (n_vertices.count(types[c]) == 0)
            fail("cell " + std::to_string(c) + " has VTK type " +
                 text_of(types[c]) +
                 ", not a vertex (1), line (3), triangle (5) or "
                 "quadrilateral (9)");
          if (end - begin != n_vertices.at(types[c]))
            fail("cell " + std::to_string(c) + " of type " +
                 std::to_string(int(types[c])) + " has " +
                 text_of(end - begin) + " vertices");
          std::vector<unsigned int> vertices;
          for (auto k = std::size_t(begin); k < std::size_t(end); ++k)
            {
              const double v = connectivity[k];
              if (v < 0 || v >= n_points || v != std::floor(v))
                fail("cell " + std::to_string(c) + " refers to point " +
                     text_of(v) + ", but there are " +
                     std::to_string(n_points) + " points");
              vertices.push_back(static_cast<unsigned int>(v));
            }
          begin = end;
          if (std::set<unsigned int>(vertices.begin(), vertices.end()).size() !=
              vertices.size())
            fail("cell " + std::to_string(c) + " names a point twice");
          const double id = ids.empty() ? 0 : ids[c];
          if (id < 0 || id >= 255 || id != std::floor(id))
            fail("MaterialID " + text_of(id) + " of cell " + std::to_string(c) +
                 " is not in 0..254");
          if (types[c] == 3)
            add_boundary_line(mesh,
                              vertices[0],
                              vertices[1],
                              static_cast<types::boundary_id>(id));
          else if (types[c] != 1)
            add_cell(mesh, vertices, static_cast<types::material_id>(id));
        }
      if (mesh.cells.empty())
        fail("no triangles or quadrilaterals");
      GridTools::delete_unused_vertices(mesh.vertices,
                                        mesh.cells,
                                        mesh.subcells);
      return mesh;
    }



    void
    check_vtk(const std::string &file)
    {
      Lines       lines(file);
      std::string line;
      const auto  expect_line = [&](const std::string &what) {
        if (!lines.next(line))
          lines.fail("the file ends where " + what + " should be");
        return trim(line);
      };
      if (expect_line("the header").rfind("# vtk DataFile Version", 0) != 0)
        lines.fail("not a legacy VTK file (no '# vtk DataFile Version' "
                   "header; knee_contact reads ASCII .vtk, not .vtu)");
      expect_line("the title");
      if (upper(expect_line("ASCII")) != "ASCII")
        lines.fail("a binary VTK file: knee_contact reads ASCII .vtk");
      if (upper(expect_line("DATASET")) != "DATASET UNSTRUCTURED_GRID")
        lines.fail("DATASET is not UNSTRUCTURED_GRID");

      // The rest as whitespace separated words, with their lines.
      std::vector<std::pair<std::string, unsigned long>> words;
      while (lines.next(line))
        {
          std::stringstream stream(line);
          std::string       word;
          while (stream >> word)
            words.emplace_back(word, lines.number);
        }
      std::size_t at   = 0;
      const auto  word = [&](const std::string &what) -> const std::string  &{
        if (at >= words.size())
          lines.fail("the file ends where " + what + " should be");
        lines.number = words[at].second;
        return words[at++].first;
      };
      const auto count = [&](const std::string &what) {
        const std::string &text = word(what);
        const long long    n    = to_integer(text, lines);
        if (n < 0 || static_cast<std::uintmax_t>(n) > lines.size)
          lines.fail(what + " " + text + " is more than the file's " +
                     std::to_string(lines.size) + " bytes can hold");
        return static_cast<std::size_t>(n);
      };
      const auto keyword = [&](const std::string &expected) {
        const std::string &found = word(expected);
        if (upper(found) != expected)
          lines.fail("expected " + expected + ", found '" + found + "'");
      };

      keyword("POINTS");
      const std::size_t n_points = count("point count");
      word("the point type");
      for (std::size_t i = 0; i < 3 * n_points; ++i)
        to_number(word("a coordinate"), lines);
      keyword("CELLS");
      const std::size_t        n_cells = count("cell count");
      const std::size_t        n_ints  = count("cell list size");
      std::vector<std::size_t> sizes;
      std::size_t              used = 0;
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const std::size_t n = count("vertex count");
          if (n < 1 || n > 4)
            lines.fail("cell " + std::to_string(c) + " has " +
                       std::to_string(n) + " vertices");
          std::set<long long> distinct;
          for (std::size_t k = 0; k < n; ++k)
            {
              const long long v = to_integer(word("a vertex"), lines);
              if (v < 0 || static_cast<std::size_t>(v) >= n_points)
                lines.fail("cell " + std::to_string(c) + " refers to point " +
                           std::to_string(v) + ", but there are " +
                           std::to_string(n_points) + " points");
              distinct.insert(v);
            }
          if (distinct.size() != n)
            lines.fail("cell " + std::to_string(c) + " names a point twice");
          sizes.push_back(n);
          used += n + 1;
        }
      if (used != n_ints)
        lines.fail("CELLS says " + std::to_string(n_ints) +
                   " numbers, the cells have " + std::to_string(used));
      keyword("CELL_TYPES");
      if (count("cell type count") != n_cells)
        lines.fail("CELL_TYPES count differs from CELLS");
      for (std::size_t c = 0; c < n_cells; ++c)
        {
          const long long type = to_integer(word("a cell type"), lines);
          // 1 vertex, 3 line, 5 triangle, 9 quadrilateral.
          const std::map<long long, std::size_t> n_vertices = {{1, 1},
                                                               {3, 2},
                                                               {5, 3},
                                                               {9, 4}};
          if (n_vertices.count(type) == 0)
            lines.fail("cell type " + std::to_string(type) +
                       " is not a vertex (1), line (3), triangle (5) or "
                       "quadrilateral (9); knee_contact reads linear 2D "
                       "cells");
          if (n_vertices.at(type) != sizes[c])
            lines.fail("cell " + std::to_string(c) + " of type " +
                       std::to_string(type) + " has " +
                       std::to_string(sizes[c]) + " vertices");
        }
      if (at == words.size())
        return;
      keyword("CELL_DATA");
      if (count("cell data count") != n_cells)
        lines.fail("CELL_DATA count differs from CELLS");
      while (at < words.size())
        {
          keyword("SCALARS");
          const std::string name = word("a field name");
          if (name != "MaterialID" && name != "ManifoldID")
            lines.fail("field '" + name +
                       "': knee_contact reads MaterialID and ManifoldID "
                       "(boundary ids are the MaterialID of line cells)");
          if (word("the field type") != "int")
            lines.fail("field '" + name + "' must have type int");
          if (words[at].first == "1")
            ++at;
          keyword("LOOKUP_TABLE");
          word("the lookup table");
          for (std::size_t c = 0; c < n_cells; ++c)
            {
              const long long id = to_integer(word("an id"), lines);
              if (id < 0 || id >= 255)
                lines.fail(name + " " + std::to_string(id) +
                           " is not in 0..254");
            }
        }
    }



    void
    split_into_quadrilaterals(
      Description<2>                                  &mesh,
      const std::map<types::boundary_id, Point<2>> &circles)
    {
      // Each edge gets one midpoint, shared by the cells beside it, so the
      // split mesh is conforming.
      std::map<std::pair<unsigned int, unsigned int>, unsigned int> midpoint;
      const auto middle = [&](const unsigned int a, const unsigned int b) {
        const auto key = std::minmax(a, b);
        const auto it  = midpoint.find(key);
        if (it != midpoint.end())
          return it->second;
        midpoint[key] = mesh.vertices.size();
        mesh.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
        return static_cast<unsigned int>(mesh.vertices.size() - 1);
      };

      std::vector<CellData<2>> cells;
      for (const CellData<2> &cell : mesh.cells)
        {
          const auto &v = cell.vertices;
          // Corners in counter-clockwise order.
          std::vector<unsigned int> ring =
            v.size() == 3 ? std::vector<unsigned int>{v[0], v[1], v[2]}
                          : std::vector<unsigned int>{v[0], v[1], v[3], v[2]};
          Point<2> centre;
          for (const unsigned int k : ring)
            centre += mesh.vertices[k] / double(ring.size());
          const unsigned int c = mesh.vertices.size();
          mesh.vertices.push_back(centre);
          for (unsigned int k = 0; k < ring.size(); ++k)
            {
              const unsigned int next = ring[(k + 1) % ring.size()],
                                 prev =
                                   ring[(k + ring.size() - 1) % ring.size()];
              CellData<2> child(4);
              // Round the child counter-clockwise: corner, midpoint to the
              // next corner, centre, midpoint to the previous one; deal.II
              // lists them lexicographically (0 1 3 2 round the cell).
              child.vertices    = {ring[k],
                                   middle(ring[k], next),
                                   middle(prev, ring[k]),
                                   c};
              child.material_id = cell.material_id;
              child.manifold_id = cell.manifold_id;
              cells.push_back(child);
            }
        }
      mesh.cells = std::move(cells);

      std::vector<CellData<1>> lines;
      for (const CellData<1> &line : mesh.subcells.boundary_lines)
        {
          const auto key = std::minmax(line.vertices[0], line.vertices[1]);
          const auto it  = midpoint.find(key);
          if (it == midpoint.end())
            continue; // not an edge of the mesh: deal.II would refuse it
          const auto circle = circles.find(line.boundary_id);
          if (circle != circles.end())
            {
              // On the arc, not on its chord.
              const Point<2> &c = circle->second;
              const double    r = mesh.vertices[line.vertices[0]].distance(c);
              const Tensor<1, 2> d = mesh.vertices[it->second] - c;
              if (d.norm() > 0)
                mesh.vertices[it->second] = c + r / d.norm() * d;
            }
          for (const unsigned int end : {0u, 1u})
            {
              CellData<1> half = line;
              half.vertices    = {line.vertices[end], it->second};
              lines.push_back(half);
            }
        }
      mesh.subcells.boundary_lines = std::move(lines);
    }
  } // namespace mesh_readers
} // namespace knee_contact
