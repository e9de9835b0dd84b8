#include <knee_contact/base/input.h>
#include <knee_contact/mesh/gmsh_input.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <fstream>
#include <map>
#include <sstream>
#include <tuple>
#include <vector>

// Entities in several physical groups. Gmsh gives an entity every physical
// group that names it (a curve can be "all outer sides" and "the loaded
// side"); deal.II 9.4's GridIn::read_msh reads one tag per entity and
// refuses more ("More than one tag is not supported!"), and in the 2.2
// format Gmsh writes such an element once per group. No library picks a
// group for a scene, so the file is rewritten here with one group per
// entity before deal.II reads it.
namespace knee_contact
{
  namespace gmsh_input
  {
    namespace
    {
      using mesh_readers::internal::words;

      std::string
      join(const std::vector<std::string> &fields)
      {
        std::string line;
        for (const auto &field : fields)
          line += (line.empty() ? "" : " ") + field;
        return line;
      }

      const char *
      entity_name(const unsigned int dim)
      {
        return dim == 0   ? "point"
               : dim == 1 ? "curve"
               : dim == 2 ? "surface"
                          : "volume";
      }

      /**
       * The one group of an entity of dimension @p entity_dim with the
       * physical groups @p groups (at least two): the one the scene names,
       * or the first if it names none.
       */
      std::string
      choose(const std::string              &file,
             const unsigned int              entity_dim,
             const std::string              &entity,
             const std::vector<std::string> &groups,
             const unsigned int              mesh_dim,
             const std::set<unsigned int>   &cell_ids,
             const std::set<unsigned int>   &facet_ids)
      {
        const std::set<unsigned int> *used = entity_dim == mesh_dim ? &cell_ids
                                             : entity_dim + 1 == mesh_dim
                                               ? &facet_ids
                                               : nullptr;
        std::vector<std::string>      named;
        if (used != nullptr)
          for (const auto &group : groups)
            {
              const auto id = input::number(group);
              if (id && *id >= 0 && used->count(static_cast<unsigned int>(*id)))
                named.push_back(group);
            }
        if (named.size() > 1)
          {
            std::string list;
            for (const auto &group : groups)
              list += (list.empty() ? "" : ", ") + group;
            throw std::runtime_error(input::cap(
              "Mesh/File: '" + file + "': Gmsh " + entity_name(entity_dim) +
              " " + entity + " is in the physical groups " + list +
              " and the scene names " + named[0] + " and " + named[1] +
              ": which one it is would be a guess (give it one group)"));
          }
        return named.empty() ? groups[0] : named[0];
      }
    } // namespace



    std::string
    one_group_per_entity(const std::string            &msh,
                         const std::string            &file,
                         const unsigned int            mesh_dim,
                         const std::set<unsigned int> &cell_ids,
                         const std::set<unsigned int> &facet_ids)
    {
      std::ifstream            in(msh);
      std::vector<std::string> lines;
      std::string              line;
      while (std::getline(in, line))
        {
          if (!line.empty() && line.back() == '\r')
            line.pop_back();
          lines.push_back(line);
        }
      bool        changed = false;
      std::string version;
      for (std::size_t i = 0; i + 1 < lines.size(); ++i)
        if (lines[i] == "$MeshFormat")
          version = words(lines[i + 1]).at(0);

      if (version.rfind("4", 0) == 0)
        {
          // $Entities: counts of points, curves, surfaces, volumes; a
          // point is 'tag x y z n_phys tags...', the others 'tag box(6)
          // n_phys tags... n_bounding tags...'.
          for (std::size_t i = 0; i < lines.size(); ++i)
            if (lines[i] == "$Entities")
              {
                const auto counts = words(lines[++i]);
                for (unsigned int dim = 0; dim < 4; ++dim)
                  for (unsigned long long k = 0; k < std::stoull(counts[dim]);
                       ++k)
                    {
                      auto              fields = words(lines[++i]);
                      const std::size_t p      = dim == 0 ? 4 : 7;
                      const auto        n      = std::stoull(fields[p]);
                      if (n < 2)
                        continue;
                      const std::vector<std::string> groups(
                        fields.begin() + p + 1, fields.begin() + p + 1 + n);
                      const std::string kept = choose(file,
                                                      dim,
                                                      fields[0],
                                                      groups,
                                                      mesh_dim,
                                                      cell_ids,
                                                      facet_ids);
                      fields.erase(fields.begin() + p,
                                   fields.begin() + p + 1 + n);
                      fields.insert(fields.begin() + p, {"1", kept});
                      lines[i] = join(fields);
                      changed  = true;
                    }
                break;
              }
        }
      else
        {
          // 2.2: 'number type n_tags physical elementary ... nodes'; an
          // element of an entity in several groups appears once per group.
          for (std::size_t i = 0; i < lines.size(); ++i)
            if (lines[i] == "$Elements")
              {
                const std::size_t first = i + 2;
                const std::size_t n     = std::stoull(words(lines[i + 1])[0]);
                // (type, entity, nodes) -> its lines and their groups.
                std::map<std::tuple<std::string, std::string, std::string>,
                         std::vector<std::size_t>>
                  copies;
                for (std::size_t e = first; e < first + n; ++e)
                  {
                    const auto fields = words(lines[e]);
                    const auto n_tags = std::stoull(fields[2]);
                    if (n_tags < 2)
                      continue;
                    std::vector<std::string> nodes(fields.begin() + 3 + n_tags,
                                                   fields.end());
                    copies[{fields[1], fields[4], join(nodes)}].push_back(e);
                  }
                std::vector<bool> dropped(lines.size(), false);
                for (const auto &[key, copy_lines] : copies)
                  if (copy_lines.size() > 1)
                    {
                      std::vector<std::string> groups;
                      for (const auto e : copy_lines)
                        groups.push_back(words(lines[e])[3]);
                      const long long type = std::stoll(std::get<0>(key));
                      // Gmsh's element types: points 15, lines 1, triangles
                      // 2 and quadrilaterals 3, tetrahedra 4 and hexahedra 5
                      // (check_msh admits no others).
                      const unsigned int dim      = type == 15               ? 0
                                                    : type == 1              ? 1
                                                    : type == 2 || type == 3 ? 2
                                                                             : 3;
                      const std::string  kept     = choose(file,
                                                      dim,
                                                      std::get<1>(key),
                                                      groups,
                                                      mesh_dim,
                                                      cell_ids,
                                                      facet_ids);
                      bool               kept_one = false;
                      for (const auto e : copy_lines)
                        if (words(lines[e])[3] == kept && !kept_one)
                          kept_one = true;
                        else
                          dropped[e] = true;
                      changed = true;
                    }
                if (changed)
                  {
                    std::size_t n_kept = 0;
                    for (std::size_t e = first; e < first + n; ++e)
                      n_kept += dropped[e] ? 0 : 1;
                    lines[i + 1] = std::to_string(n_kept);
                    std::vector<std::string> kept_lines;
                    for (std::size_t l = 0; l < lines.size(); ++l)
                      if (!dropped[l])
                        kept_lines.push_back(lines[l]);
                    lines = std::move(kept_lines);
                  }
                break;
              }
        }
      if (!changed)
        return "";
      std::string text;
      for (const auto &l : lines)
        text += l + '\n';
      return text;
    }
  } // namespace gmsh_input
} // namespace knee_contact
