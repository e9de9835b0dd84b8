#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

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

      Description<2>                    mesh;
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
  } // namespace mesh_readers
} // namespace knee_contact
