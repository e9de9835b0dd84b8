#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <memory>
#include <set>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    namespace
    {
      /**
       * The lines of a deck and of the decks it includes (*Include), in
       * order; errors name the file and line they are in.
       */
      class Deck
      {
      public:
        explicit Deck(const std::string &file)
        {
          open(file);
        }

        bool
        next(std::string &line)
        {
          while (!files.empty())
            {
              if (files.back()->next(line))
                return true;
              last = std::move(files.back());
              files.pop_back();
            }
          return false;
        }

        /**
         * Continue with @p name (relative to the current file's folder),
         * then with the rest of the current file: *Include and INPUT=.
         */
        void
        include(const std::string &name)
        {
          const std::string path =
            std::filesystem::path(name).is_absolute()
              ? name
              : (std::filesystem::path(current().file).parent_path() / name)
                  .lexically_normal()
                  .string();
          for (const auto &file : files)
            if (std::filesystem::weakly_canonical(file->file) ==
                std::filesystem::weakly_canonical(path))
              fail("INPUT=" + name + ", which includes itself");
          if (files.size() >= 8)
            fail("INPUT= files (*Include) nested more than 8 deep");
          if (!std::filesystem::is_regular_file(path))
            fail("INPUT=" + name + ": cannot open '" + path + "'");
          open(path);
        }

        [[noreturn]] void
        fail(const std::string &what) const
        {
          (files.empty() ? *last : *files.back()).fail(what);
        }

        /** Bytes of the files read so far: no count may exceed them. */
        std::uintmax_t size = 0;

        const Lines &
        current() const
        {
          return files.empty() ? *last : *files.back();
        }

      private:
        void
        open(const std::string &file)
        {
          files.push_back(std::make_unique<Lines>(file));
          size += files.back()->size;
        }

        std::vector<std::unique_ptr<Lines>> files;
        std::unique_ptr<Lines>              last;
      };



      /**
       * A mesh as the deck defines it: a *Part, or the model as a whole
       * (the flat deck, and every instance copied into it). Nodes keep
       * three coordinates (a 2D deck's z must be 0).
       */
      struct Model
      {
        std::map<long long, Point<3>>               nodes;
        std::map<long long, std::vector<long long>> elements;
        // Elements of one dimension less than the cells (2D: two-node
        // lines, trusses and beams; 3D: triangles and quadrilaterals of
        // plane or surface type), node numbers sorted: Gmsh's .inp export
        // writes the physical curves (2D) and surfaces (3D) as these; a set
        // of them names boundary faces.
        std::map<long long, std::vector<long long>> facet_elements;
        std::map<std::string, std::set<long long>>  elsets, nsets;
        // Name -> (element number or element set, face).
        std::map<std::string, std::vector<std::pair<std::string, unsigned int>>>
                              surfaces;
        std::set<std::string> node_surfaces; // TYPE=NODE: node sets
        // The element sets of *Solid Section lines, their material ids
        // (1, 2, ... in file order) and the *Material they name.
        struct Section
        {
          std::string  elset;
          unsigned int id;
          std::string  material;
        };
        std::vector<Section> sections;
      };

      /**
       * A *Material's linear elastic constants, or why it has none that
       * knee_contact can take (only asked for when the scene takes the
       * constants from the deck).
       */
      struct MaterialBlock
      {
        bool        elastic        = false;
        double      youngs_modulus = 0, poissons_ratio = 0;
        std::string problem;
      };

      /**
       * A *Instance: a copy of a part moved as its data lines say: a
       * translation, then a rotation about the axis from a to b by an angle
       * in degrees, right-handed about a->b (Abaqus applies them in this
       * order); in 2D the axis must be parallel to z.
       */
      struct Placement
      {
        Tensor<1, 3> translation;
        Point<3>     centre;
        Tensor<1, 3> axis; // unit vector
        double       angle = 0;

        Point<3>
        operator()(const Point<3> &p) const
        {
          // Rodrigues' rotation formula.
          const Tensor<1, 3> d = p + translation - centre;
          const double       c = std::cos(angle), s = std::sin(angle);
          return centre + c * d + s * cross_product_3d(axis, d) +
                 (1 - c) * (axis * d) * axis;
        }
      };

      /**
       * The nodes of face S(k+1) of an element with nodes @p nodes in
       * Abaqus' numbering, round the face: 2D, the element's nodes k and
       * k+1; C3D4 and C3D8 as Abaqus' element library lists their faces.
       */
      template <int dim>
      std::vector<long long>
      face_nodes(const std::vector<long long> &nodes, const unsigned int k)
      {
        if (dim == 2)
          return {nodes[k], nodes[(k + 1) % nodes.size()]};
        static const std::vector<std::vector<unsigned int>> tet = {{0, 1, 2},
                                                                   {0, 3, 1},
                                                                   {1, 3, 2},
                                                                   {2, 3, 0}};
        static const std::vector<std::vector<unsigned int>> hex = {
          {0, 1, 2, 3},
          {4, 7, 6, 5},
          {0, 4, 5, 1},
          {1, 5, 6, 2},
          {2, 6, 7, 3},
          {3, 7, 4, 0}};
        std::vector<long long> result;
        for (const unsigned int i : (nodes.size() == 4 ? tet : hex)[k])
          result.push_back(nodes[i]);
        return result;
      }

      /**
       * The number of nodes of Abaqus element @p type if it is a linear
       * element of cell dimension @p d in a mesh of dimension @p dim, else
       * 0: lines (trusses, beams), plane triangles and quadrilaterals
       * (CPS, CPE with R, H, I; in 3D also the surface elements SFM3D),
       * tetrahedra and hexahedra (C3D4, C3D8 with R, H, I).
       */
      unsigned int
      element_nodes(const std::string &type, const int d, const int dim)
      {
        const auto variant = [&](const std::string &base) {
          return type.rfind(base, 0) == 0 &&
                 type.find_first_not_of("RHI", base.size()) ==
                   std::string::npos;
        };
        if (d == 1)
          return variant("T2D2") || variant("T3D2") || variant("B21") ||
                     variant("B31")
                   ? 2
                   : 0;
        if (d == 2)
          return variant("CPS3") || variant("CPE3") ||
                     (dim == 3 && variant("SFM3D3"))
                   ? 3
                 : variant("CPS4") || variant("CPE4") ||
                     (dim == 3 && variant("SFM3D4"))
                   ? 4
                   : 0;
        return variant("C3D4") ? 4 : variant("C3D8") ? 8 : 0;
      }

      /**
       * The INPUT= of a keyword line as written (a path keeps its case), or
       * "".
       */
      std::string
      input_of(const std::vector<std::string> &keyword_fields)
      {
        for (std::size_t i = 1; i < keyword_fields.size(); ++i)
          {
            const auto equal = keyword_fields[i].find('=');
            if (equal != std::string::npos &&
                upper(trim(keyword_fields[i].substr(0, equal))) == "INPUT")
              return trim(keyword_fields[i].substr(equal + 1));
          }
        return "";
      }

      /** The file of an *Include line. */
      std::string
      include_input(const std::vector<std::string> &keyword_fields,
                    const Deck                     &deck)
      {
        const std::string input = input_of(keyword_fields);
        if (input.empty())
          deck.fail("*Include without INPUT=");
        return input;
      }



      std::vector<long long>
      sorted(std::vector<long long> nodes)
      {
        std::sort(nodes.begin(), nodes.end());
        return nodes;
      }
    } // namespace



    unsigned int
    abaqus_dimension(const std::string &file)
    {
      Deck        deck(file);
      std::string line;
      bool        solid = false;
      while (deck.next(line))
        {
          std::string text = trim(line);
          if (text.empty() || text[0] != '*' || text.rfind("**", 0) == 0)
            continue;
          std::string more;
          while (text.back() == ',' && deck.next(more))
            text += trim(more);
          const auto        keyword_fields = fields(text);
          const std::string keyword        = upper(keyword_fields[0]);
          if (keyword == "*INCLUDE")
            {
              deck.include(include_input(keyword_fields, deck));
            }
          else if (keyword == "*ELEMENT")
            {
              const std::string type = option(keyword_fields, "TYPE");
              // Quadratic ones too: the 3D reader names what it refuses.
              solid |= type.rfind("C3D", 0) == 0;
            }
        }
      // Plane elements beside solid ones are boundary faces.
      return solid ? 3 : 2;
    }



    template <int dim>
    Description<dim>
    read_abaqus(const std::string                         &file,
                const std::map<std::string, unsigned int> &element_sets,
                const std::map<std::string, unsigned int> &boundary_sets)
    {
      Deck deck(file);
      // The whole model: the flat deck's mesh and every instance's copy,
      // numbered apart; the sets of an instance are named INSTANCE.SET.
      Model                                model;
      std::map<std::string, Model>         parts;
      std::set<std::string>                instance_names;
      std::map<std::string, MaterialBlock> materials;
      MaterialBlock *open_material    = nullptr; // in a *Material
      Model         *scope            = &model;  // where definitions go
      bool           in_assembly      = false;
      unsigned int   n_sections       = 0;
      long long      next_node        = 0; // free numbers of
      long long      next_element     = 0; // the model
      const auto     fail_if_too_many = [&](const Model &m) {
        // At most one number per byte of the files: counts beyond that are
        // not a mesh but an attack on memory.
        if (m.nodes.size() + m.elements.size() + m.facet_elements.size() >
            deck.size)
          deck.fail("more nodes and elements than the deck can hold");
      };

      std::string  line;
      std::string  block; // the keyword whose data lines follow
      std::string  block_set;
      std::string  set_instance; // INSTANCE= of an assembly-level set
      bool         generate        = false;
      unsigned int n_element_nodes = 0;
      bool         facets          = false; // *Element of boundary faces

      // "INSTANCE.NAME" of an assembly-level reference: the instance's
      // copy of a part's set, or an element or node number of the
      // instance; or a set of the scope.
      const auto qualified = [&](const std::string &name) {
        const auto dot = name.find('.');
        return dot != std::string::npos &&
               instance_names.count(name.substr(0, dot)) != 0;
      };
      // Element and node numbers of instances in the model.
      std::map<std::string, std::pair<long long, long long>> offsets;

      // Copy @p part as instance @p name into the model, moved by @p place.
      const auto add_instance = [&](const std::string &name,
                                    const Model       &part,
                                    const Placement   &place) {
        const long long node_offset    = next_node;
        const long long element_offset = next_element;
        offsets[name]                  = {node_offset, element_offset};
        for (const auto &[id, p] : part.nodes)
          {
            model.nodes[node_offset + id] = place(p);
            next_node = std::max(next_node, node_offset + id + 1);
          }
        const auto element_id = [&](const long long id) {
          next_element = std::max(next_element, element_offset + id + 1);
          return element_offset + id;
        };
        for (const auto &[id, nodes] : part.elements)
          {
            auto &copy = model.elements[element_id(id)];
            for (const long long n : nodes)
              copy.push_back(node_offset + n);
          }
        for (const auto &[id, facet] : part.facet_elements)
          {
            auto &copy = model.facet_elements[element_id(id)];
            for (const long long n : facet)
              copy.push_back(node_offset + n);
          }
        for (const auto &[set, ids] : part.elsets)
          for (const long long id : ids)
            model.elsets[name + "." + set].insert(element_offset + id);
        for (const auto &[set, ids] : part.nsets)
          for (const long long id : ids)
            model.nsets[name + "." + set].insert(node_offset + id);
        for (const auto &[surface, faces] : part.surfaces)
          {
            auto &copy = model.surfaces[name + "." + surface];
            for (const auto &[owner, face] : faces)
              copy.emplace_back(
                std::isdigit(static_cast<unsigned char>(owner[0]))
                  ? std::to_string(element_offset + std::stoll(owner))
                  : name + "." + owner,
                face);
          }
        for (const auto &surface : part.node_surfaces)
          model.node_surfaces.insert(name + "." + surface);
        for (const auto &section : part.sections)
          model.sections.push_back(
            {name + "." + section.elset, section.id, section.material});
        fail_if_too_many(model);
      };

      while (deck.next(line))
        {
          std::string text = trim(line);
          if (text.empty() || text.rfind("**", 0) == 0)
            continue;
          if (text[0] == '*')
            {
              // A keyword line that ends with a comma goes on.
              std::string more;
              while (text.back() == ',' && deck.next(more))
                text += trim(more);
              const auto        keyword_fields = fields(text);
              const std::string keyword        = upper(keyword_fields[0]);
              // *Include is textual: the file's lines stand in place of
              // this one, so a block (*Node, *Element, ...) goes on in it.
              if (keyword == "*INCLUDE")
                {
                  deck.include(include_input(keyword_fields, deck));
                  continue;
                }
              // INPUT= on another keyword (*Node, input=nodes.inp): the
              // keyword's data lines are that file's; the handlers below
              // read no lines themselves but *Instance's.
              if (const std::string input = input_of(keyword_fields);
                  !input.empty())
                {
                  if (keyword == "*INSTANCE")
                    deck.fail("*Instance with INPUT=: knee_contact reads "
                              "an instance's data lines in the deck");
                  deck.include(input);
                }
              block        = "";
              set_instance = "";
              // A *Material's definition is the keywords up to the next
              // that is not one of its options.
              const std::set<std::string> material_options = {"*ELASTIC",
                                                              "*DENSITY",
                                                              "*EXPANSION",
                                                              "*DAMPING",
                                                              "*CONDUCTIVITY",
                                                              "*SPECIFIC HEAT"};
              // Behaviours beyond linear elasticity: the material's constants
              // are not all of it.
              const std::set<std::string> beyond_elastic = {
                "*PLASTIC",
                "*HYPERELASTIC",
                "*HYPOELASTIC",
                "*HYPERFOAM",
                "*VISCOELASTIC",
                "*CREEP",
                "*POROUS ELASTIC",
                "*USER MATERIAL",
                "*DRUCKER PRAGER",
                "*MOHR COULOMB",
                "*CAP PLASTICITY",
                "*CRUSHABLE FOAM",
                "*DAMAGE INITIATION",
                "*DAMAGE EVOLUTION",
                "*MULLINS EFFECT"};
              if (open_material != nullptr &&
                  beyond_elastic.count(keyword) != 0)
                {
                  if (open_material->problem.empty())
                    open_material->problem =
                      "it has " + keyword_fields[0] +
                      " (knee_contact is linear elastic)";
                  continue;
                }
              if (material_options.count(keyword) == 0)
                open_material = nullptr;
              generate          = has_flag(keyword_fields, "GENERATE");
              const auto refuse = [&](const std::string &instead) {
                deck.fail(keyword_fields[0] +
                          ": knee_contact does not read "
                          "it; " +
                          instead);
              };
              // The NAME= of a *Part or *Material, which must be new.
              const auto new_name = [&](const std::string &what,
                                        const auto        &taken) {
                const std::string name = option(keyword_fields, "NAME");
                if (name.empty() || taken.count(name) != 0)
                  deck.fail(what + " without a name, or a second " + what +
                            " named '" + name + "'");
                return name;
              };
              if (keyword == "*PART")
                {
                  scope = &parts[new_name("*Part", parts)];
                }
              else if (keyword == "*END PART")
                {
                  scope = &model;
                }
              else if (keyword == "*ASSEMBLY")
                in_assembly = true;
              else if (keyword == "*END ASSEMBLY")
                in_assembly = false;
              else if (keyword == "*INSTANCE")
                {
                  const std::string name = option(keyword_fields, "NAME");
                  const std::string part = option(keyword_fields, "PART");
                  if (!in_assembly || name.empty() || part.empty() ||
                      parts.count(part) == 0 || instance_names.count(name))
                    deck.fail("*Instance needs a NAME of its own and the "
                              "PART of a *Part above, inside *Assembly");
                  // Up to two data lines (translation; rotation) before
                  // *End Instance.
                  Placement                place;
                  std::vector<std::string> data;
                  std::string              next;
                  unsigned int             n_data = 0;
                  while (deck.next(next))
                    {
                      const std::string t = trim(next);
                      if (t.empty() || t.rfind("**", 0) == 0)
                        continue;
                      if (upper(t) == "*END INSTANCE")
                        break;
                      if (t[0] == '*')
                        deck.fail("an *Instance with its own keywords (" +
                                  fields(t)[0] +
                                  "): knee_contact reads instances of parts");
                      const auto v = fields(t);
                      ++n_data;
                      if (n_data == 1 && v.size() == 3)
                        {
                          for (unsigned int d = 0; d < 3; ++d)
                            place.translation[d] =
                              to_number(v[d], deck.current());
                          if (dim == 2 && place.translation[2] != 0)
                            deck.fail("an instance translated along z: "
                                      "2D meshes lie in the x-y plane");
                        }
                      else if (n_data == 2 && v.size() == 7)
                        {
                          std::array<double, 7> r;
                          for (unsigned int i = 0; i < 7; ++i)
                            r[i] = to_number(v[i], deck.current());
                          place.centre = Point<3>(r[0], r[1], r[2]);
                          place.axis =
                            Point<3>(r[3], r[4], r[5]) - place.centre;
                          if (place.axis.norm() == 0)
                            deck.fail("an instance rotated about an axis "
                                      "from a point to itself");
                          if (dim == 2 &&
                              (place.axis[0] != 0 || place.axis[1] != 0))
                            deck.fail("an instance rotated about an axis "
                                      "that is not parallel to z: 2D "
                                      "meshes lie in the x-y plane");
                          place.axis /= place.axis.norm();
                          place.angle = r[6] * numbers::PI / 180;
                        }
                      else
                        deck.fail("an *Instance data line is a translation "
                                  "'x, y, z' and then a rotation 'a_x, a_y, "
                                  "a_z, b_x, b_y, b_z, angle'");
                    }
                  instance_names.insert(name);
                  add_instance(name, parts[part], place);
                }
              else if (keyword == "*NODE")
                {
                  block     = keyword;
                  block_set = option(keyword_fields, "NSET");
                }
              else if (keyword == "*ELEMENT")
                {
                  if (in_assembly)
                    deck.fail("*Element in the assembly: knee_contact reads "
                              "elements of parts");
                  const std::string type = option(keyword_fields, "TYPE");
                  n_element_nodes        = element_nodes(type, dim, dim);
                  facets                 = n_element_nodes == 0;
                  // Facets: faces of the cells, and in 3D also lines
                  // (Gmsh writes physical curves so), which name no face.
                  for (int d = dim - 1; d >= 1 && n_element_nodes == 0; --d)
                    n_element_nodes = element_nodes(type, d, dim);
                  if (n_element_nodes == 0)
                    deck.fail(
                      "element type '" + type + "' is not a linear " +
                      (dim == 2
                         ? "plane element (a 2D deck: knee_contact reads "
                           "CPS3, CPE3, CPS4, CPE4 and their R, H, I "
                           "variants, and two-node lines T2D2, T3D2, "
                           "B21, B31 as boundary edges"
                         : "solid element (a 3D deck: knee_contact reads "
                           "C3D4 and C3D8 and their R, H, I variants, "
                           "and CPS3, CPE3, CPS4, CPE4, SFM3D3, SFM3D4 "
                           "as boundary faces") +
                      "; mesh with linear elements)");
                  block     = keyword;
                  block_set = option(keyword_fields, "ELSET");
                }
              else if (keyword == "*ELSET" || keyword == "*NSET")
                {
                  block     = keyword;
                  block_set = option(keyword_fields,
                                     keyword == "*ELSET" ? "ELSET" : "NSET");
                  if (block_set.empty())
                    deck.fail(keyword + " without a name");
                  set_instance = option(keyword_fields, "INSTANCE");
                  if (!set_instance.empty() &&
                      (!in_assembly || offsets.count(set_instance) == 0))
                    deck.fail(keyword + " of instance '" + set_instance +
                              "', which no *Instance above defines");
                  (keyword == "*ELSET" ? scope->elsets
                                       : scope->nsets)[block_set];
                }
              else if (keyword == "*SURFACE")
                {
                  block_set = option(keyword_fields, "NAME");
                  if (block_set.empty())
                    deck.fail("*Surface without a name");
                  const std::string type = option(keyword_fields, "TYPE");
                  if (type == "NODE")
                    {
                      block = "*NSET";
                      scope->nsets[block_set];
                      scope->node_surfaces.insert(block_set);
                    }
                  else if (type.empty() || type == "ELEMENT")
                    {
                      block = keyword;
                      scope->surfaces[block_set];
                    }
                  else
                    refuse("*Surface, type=" + type +
                           " is a rigid (analytical) surface: model the "
                           "rigid body as a stiff body of the mesh or as a "
                           "displacement condition");
                }
              else if (keyword == "*SOLID SECTION")
                {
                  const std::string set = option(keyword_fields, "ELSET");
                  if (set.empty())
                    deck.fail("*Solid Section without ELSET");
                  scope->sections.push_back(
                    {set, ++n_sections, option(keyword_fields, "MATERIAL")});
                }
              else if (keyword == "*MATERIAL")
                {
                  open_material = &materials[new_name("*Material", materials)];
                }
              else if (keyword == "*ELASTIC")
                {
                  if (open_material == nullptr)
                    deck.fail("*Elastic outside a *Material");
                  const std::string type = option(keyword_fields, "TYPE");
                  if (!type.empty() && type != "ISOTROPIC")
                    open_material->problem = "*Elastic, type=" + type +
                                             " (knee_contact's materials are "
                                             "isotropic)";
                  else if (!option(keyword_fields, "DEPENDENCIES").empty())
                    open_material->problem = "*Elastic with field dependencies";
                  else
                    block = keyword; // its data lines: E, nu
                }
              else if (keyword == "*SHELL SECTION" ||
                       keyword == "*MEMBRANE SECTION")
                refuse("shells and membranes are not plane solids: mesh the "
                       "body with CPE/CPS elements");
              else if (keyword == "*RIGID BODY")
                refuse("model the rigid body as a stiff body of the mesh or "
                       "as a displacement condition (Boundary conditions)");
              else if (keyword == "*TIE")
                refuse("bodies that share nodes are bonded: merge the tied "
                       "surfaces' nodes, or make the two sides a contact "
                       "interface");
              else if (keyword == "*CONTACT PAIR" || keyword == "*CONTACT" ||
                       keyword == "*SURFACE INTERACTION")
                refuse("contact is defined in the scene: name the surfaces "
                       "in Mesh/Abaqus boundary sets and pair them in "
                       "Contact/Interface N (remove the deck's contact "
                       "definitions)");
              // Every other keyword (materials, steps, loads, ...) and its
              // data is not mesh: skipped.
              continue;
            }

          auto values = fields(text);
          if (block == "*ELASTIC")
            {
              // E, nu[, temperature]: one line is a constant material;
              // more are a temperature table. Only a scene that takes the
              // constants from the deck needs them: what is not 'E, nu' is
              // that material's problem, not the deck's.
              const auto E  = values.size() >= 2 && values.size() <= 3
                                ? input::number(values[0])
                                : std::nullopt;
              const auto nu = values.size() >= 2 && values.size() <= 3
                                ? input::number(values[1])
                                : std::nullopt;
              if (!E || !nu)
                open_material->problem =
                  "its *Elastic line '" + text + "' is not 'E, nu'";
              else if (open_material->elastic)
                open_material->problem = "*Elastic depends on temperature";
              else
                {
                  open_material->youngs_modulus = *E;
                  open_material->poissons_ratio = *nu;
                }
              open_material->elastic = true;
            }
          else if (block == "*NODE")
            {
              if (values.size() < 3 || values.size() > 4)
                deck.fail(std::string("a node needs 'number, x, y") +
                          (dim == 3 ? ", z" : "") + "' (found " +
                          std::to_string(values.size()) + " fields)");
              const long long id = to_integer(values[0], deck.current());
              if (id < 0 || id > (1ll << 40))
                deck.fail("node number " + values[0] + " out of range");
              Point<3> p;
              for (unsigned int d = 0; d + 1 < values.size(); ++d)
                p[d] = to_number(values[d + 1], deck.current());
              if (dim == 2 && p[2] != 0)
                deck.fail("node " + values[0] +
                          " has z != 0 in a 2D deck: 2D meshes lie in the "
                          "x-y plane");
              // Nodes of the assembly are reference points of rigid
              // bodies (refused where they are defined): not mesh.
              if (in_assembly)
                continue;
              if (!scope->nodes.emplace(id, p).second)
                deck.fail("node " + values[0] + " appears twice");
              if (scope == &model)
                next_node = std::max(next_node, id + 1);
              fail_if_too_many(*scope);
              if (!block_set.empty())
                scope->nsets[block_set].insert(id);
            }
          else if (block == "*ELEMENT")
            {
              // An element's node list may go on over lines that end
              // with a comma.
              std::string more;
              while (values.size() < n_element_nodes + 1 &&
                     text.back() == ',' && deck.next(more))
                {
                  text += trim(more);
                  values = fields(text);
                }
              if (values.size() != n_element_nodes + 1)
                deck.fail("element needs its number and " +
                          std::to_string(n_element_nodes) +
                          " node numbers (found " +
                          std::to_string(values.size()) + " fields)");
              const long long id = to_integer(values[0], deck.current());
              if (id < 0 || id > (1ll << 40))
                deck.fail("element number " + values[0] + " out of range");
              std::vector<long long> element;
              for (unsigned int k = 1; k < values.size(); ++k)
                {
                  element.push_back(to_integer(values[k], deck.current()));
                  if (scope->nodes.count(element.back()) == 0)
                    deck.fail("element " + values[0] + " refers to node " +
                              values[k] + ", which no *Node line gives");
                }
              if (std::set<long long>(element.begin(), element.end()).size() !=
                  element.size())
                deck.fail("element " + values[0] + " names a node twice");
              if (scope->elements.count(id) != 0 ||
                  scope->facet_elements.count(id) != 0)
                deck.fail("element " + values[0] + " appears twice");
              if (facets)
                scope->facet_elements.emplace(id, sorted(element));
              else
                scope->elements.emplace(id, element);
              if (scope == &model)
                next_element = std::max(next_element, id + 1);
              fail_if_too_many(*scope);
              if (!block_set.empty())
                scope->elsets[block_set].insert(id);
            }
          else if (block == "*ELSET" || block == "*NSET")
            {
              const bool elements = block == "*ELSET";
              auto &set = (elements ? scope->elsets : scope->nsets)[block_set];
              // Numbers of instance INSTANCE= are shifted into the model's.
              const long long shift =
                set_instance.empty() ? 0
                                     : (elements ? offsets[set_instance].second
                                                 : offsets[set_instance].first);
              if (generate)
                {
                  if (values.size() < 2 || values.size() > 3)
                    deck.fail("GENERATE needs 'first, last[, step]'");
                  const long long first = to_integer(values[0], deck.current()),
                                  last  = to_integer(values[1], deck.current()),
                                  step =
                                    values.size() == 3
                                      ? to_integer(values[2], deck.current())
                                      : 1;
                  if (step <= 0 || last < first ||
                      (last - first) / step > static_cast<long long>(deck.size))
                    deck.fail("GENERATE range '" + text +
                              "' is empty or too long");
                  for (long long i = first; i <= last; i += step)
                    set.insert(shift + i);
                }
              else
                for (const auto &value : values)
                  {
                    const std::string name = upper(value);
                    const auto &sets = elements ? scope->elsets : scope->nsets;
                    if (qualified(name) && set_instance.empty() && in_assembly)
                      {
                        // INSTANCE.number or INSTANCE.SET.
                        const auto        dot      = name.find('.');
                        const std::string instance = name.substr(0, dot);
                        const std::string member   = name.substr(dot + 1);
                        if (std::isdigit(static_cast<unsigned char>(member[0])))
                          set.insert((elements ? offsets[instance].second
                                               : offsets[instance].first) +
                                     to_integer(member, deck.current()));
                        else
                          {
                            const auto it = sets.find(name);
                            if (it == sets.end())
                              deck.fail("set '" + value +
                                        "' is not defined in its part");
                            set.insert(it->second.begin(), it->second.end());
                          }
                      }
                    else if (!value.empty() &&
                             !std::isdigit(
                               static_cast<unsigned char>(value[0])))
                      {
                        // A set made of other sets.
                        const auto it = sets.find(name);
                        if (it == sets.end())
                          deck.fail("set '" + value + "' is not defined above");
                        set.insert(it->second.begin(), it->second.end());
                      }
                    else if (in_assembly && set_instance.empty())
                      deck.fail("an assembly set names " + value +
                                " without its instance (write "
                                "INSTANCE." +
                                value + " or give INSTANCE=)");
                    else
                      set.insert(shift + to_integer(value, deck.current()));
                  }
            }
          else if (block == "*SURFACE")
            {
              const char last_face = dim == 2 ? '4' : '6';
              if (values.size() != 2 || values[1].size() != 2 ||
                  std::toupper(values[1][0]) != 'S' || values[1][1] < '1' ||
                  values[1][1] > last_face)
                deck.fail(std::string("a surface line needs 'element or "
                                      "element set, S1..S") +
                          last_face + "'");
              if (in_assembly &&
                  std::isdigit(static_cast<unsigned char>(values[0][0])))
                deck.fail("a surface of the assembly names element " +
                          values[0] +
                          " without its instance (write INSTANCE.SET)");
              scope->surfaces[block_set].emplace_back(upper(values[0]),
                                                      values[1][1] - '1');
            }
        }
      if (!parts.empty() && instance_names.empty())
        deck.fail("the deck defines parts but no *Instance of them");
      AssertThrow(!model.elements.empty(),
                  ExcMessage("Mesh/File: '" + file +
                             "' has no *Element lines with " +
                             (dim == 2 ? "plane" : "solid") + " elements"));

      // A set the scene names: as written (upper case), or the one
      // instance's copy of it if only one instance has it.
      const auto find_name = [&](const std::string &name,
                                 const auto        &sets) -> std::string {
        const std::string key = upper(name);
        if (sets.count(key) != 0 || key.find('.') != std::string::npos)
          return key;
        std::vector<std::string> copies;
        for (const auto &[set, members] : sets)
          if (set.size() > key.size() + 1 &&
              set.compare(set.size() - key.size() - 1,
                          std::string::npos,
                          "." + key) == 0)
            copies.push_back(set);
        if (copies.size() > 1)
          AssertThrow(false,
                      ExcMessage("Mesh/File: '" + file + "': the set '" + name +
                                 "' is in several instances (" + copies[0] +
                                 ", " + copies[1] +
                                 "); name one as INSTANCE.SET in the scene"));
        return copies.empty() ? key : copies[0];
      };

      // Material ids.
      std::map<std::string, unsigned int> material_of_set;
      if (element_sets.empty())
        for (const auto &section : model.sections)
          material_of_set.emplace(section.elset, section.id);
      else
        for (const auto &[name, id] : element_sets)
          material_of_set.emplace(find_name(name, model.elsets), id);
      std::map<long long, unsigned int> material;
      for (const auto &[name, id] : material_of_set)
        {
          const auto set = model.elsets.find(name);
          AssertThrow(set != model.elsets.end(),
                      ExcMessage("Mesh/Abaqus element sets: '" + file +
                                 "' has no element set '" + name + "'"));
          for (const long long e : set->second)
            {
              if (model.facet_elements.count(e) != 0)
                continue; // boundary faces, not cells
              AssertThrow(model.elements.count(e) != 0,
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
      for (const auto &element : model.elements)
        AssertThrow(material.count(element.first) != 0,
                    ExcMessage("Mesh/Abaqus element sets: element " +
                               std::to_string(element.first) + " of '" + file +
                               "' is in no set given a material id (" +
                               (element_sets.empty()
                                  ? "no *Solid Section names it"
                                  : "name its set in the scene") +
                               ")"));

      Description<dim>                  mesh;
      std::map<long long, unsigned int> vertex_of_node;
      for (const auto &[id, p] : model.nodes)
        {
          vertex_of_node[id] = mesh.vertices.size();
          Point<dim> q;
          for (unsigned int d = 0; d < dim; ++d)
            q[d] = p[d];
          mesh.vertices.push_back(q);
        }
      for (const auto &[id, element] : model.elements)
        {
          std::vector<unsigned int> vertices;
          for (const long long node : element)
            vertices.push_back(vertex_of_node[node]);
          add_cell(mesh, vertices, material[id]);
        }

      // Each material id's *Material (its *Solid Section's MATERIAL=), for
      // a scene that takes E and nu from the deck.
      std::map<long long, std::string> material_name;
      for (const auto &section : model.sections)
        if (model.elsets.count(section.elset) != 0)
          for (const long long e : model.elsets[section.elset])
            material_name.emplace(e, section.material);
      std::map<unsigned int, std::set<std::string>> names_of_id;
      for (const auto &[id, element] : model.elements)
        names_of_id[material[id]].insert(
          material_name.count(id) ? material_name[id] : "");
      for (const auto &[id, names] : names_of_id)
        {
          DeckMaterial      &deck_material = mesh.deck_materials[id];
          const std::string &name          = *names.begin();
          deck_material.name               = name;
          if (names.size() > 1)
            deck_material.problem = "its cells have the materials '" + name +
                                    "' and '" + *std::next(names.begin()) +
                                    "' in the deck";
          else if (name.empty())
            deck_material.problem =
              "no *Solid Section with MATERIAL= covers its cells";
          else if (materials.count(name) == 0)
            deck_material.problem =
              "the deck has no *Material named '" + name + "'";
          else if (!materials[name].problem.empty())
            deck_material.problem =
              "the deck's material '" + name + "': " + materials[name].problem;
          else if (!materials[name].elastic)
            deck_material.problem =
              "the deck's material '" + name + "' has no *Elastic";
          else
            {
              deck_material.youngs_modulus = materials[name].youngs_modulus;
              deck_material.poissons_ratio = materials[name].poissons_ratio;
            }
        }

      // Boundary ids: element faces of surfaces, facet elements of a set,
      // or faces with all nodes in a node set; only faces on the boundary
      // (one element) count. Faces are keyed by their sorted nodes.
      std::map<std::vector<long long>, std::vector<long long>> face_of_key;
      std::map<std::vector<long long>, unsigned int> n_elements_of_face;
      for (const auto &[id, element] : model.elements)
        for (unsigned int k = 0; k < (dim == 2              ? element.size()
                                      : element.size() == 4 ? 4
                                                            : 6);
             ++k)
          {
            const auto face           = face_nodes<dim>(element, k);
            face_of_key[sorted(face)] = face;
            ++n_elements_of_face[sorted(face)];
          }
      const auto face_name = [](const std::vector<long long> &face) {
        std::string text = "the face of nodes";
        for (const long long n : face)
          text += " " + std::to_string(n);
        return text;
      };
      std::map<std::vector<long long>, unsigned int> boundary_id;
      for (const auto &[name, id] : boundary_sets)
        {
          // A surface, else a set of facet elements, else a node set.
          std::string key = find_name(name, model.surfaces);
          if (model.surfaces.count(key) == 0)
            {
              key = find_name(name, model.elsets);
              if (model.elsets.count(key) == 0)
                key = find_name(name, model.nsets);
            }
          const auto before = boundary_id.size();
          if (model.surfaces.count(key) != 0)
            for (const auto &[owner, face] : model.surfaces[key])
              {
                std::set<long long> owners;
                if (std::isdigit(static_cast<unsigned char>(owner[0])))
                  owners.insert(std::stoll(owner));
                else
                  {
                    AssertThrow(model.elsets.count(owner) != 0,
                                ExcMessage("Mesh/File: '" + file +
                                           "': surface '" + name +
                                           "' names element set '" + owner +
                                           "', which is not defined"));
                    owners = model.elsets[owner];
                  }
                for (const long long e : owners)
                  {
                    const auto   element = model.elements.find(e);
                    const size_t n_faces = element == model.elements.end() ? 0
                                           : dim == 2 ? element->second.size()
                                           : element->second.size() == 4 ? 4
                                                                         : 6;
                    AssertThrow(
                      face < n_faces,
                      ExcMessage("Mesh/File: '" + file + "': surface '" + name +
                                 "' names face S" + std::to_string(face + 1) +
                                 " of element " + std::to_string(e) +
                                 ", which has no such face"));
                    boundary_id[sorted(
                      face_nodes<dim>(element->second, face))] = id;
                  }
              }
          else if (model.elsets.count(key) != 0 && !model.elsets[key].empty() &&
                   std::all_of(model.elsets[key].begin(),
                               model.elsets[key].end(),
                               [&](const long long e) {
                                 return model.facet_elements.count(e) != 0;
                               }))
            for (const long long e : model.elsets[key])
              boundary_id[model.facet_elements[e]] = id;
          else if (model.nsets.count(key) != 0)
            {
              const auto &set = model.nsets[key];
              for (const auto &[face, n] : n_elements_of_face)
                if (n == 1 && std::all_of(face.begin(),
                                          face.end(),
                                          [&](const long long node) {
                                            return set.count(node) != 0;
                                          }))
                  boundary_id[face] = id;
            }
          else
            AssertThrow(false,
                        ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                   "' has no surface, node set or set of " +
                                   (dim == 2 ? "line" : "face") +
                                   " elements '" + name + "'"));
          AssertThrow(boundary_id.size() > before,
                      ExcMessage("Mesh/Abaqus boundary sets: surface or node "
                                 "set '" +
                                 name + "' of '" + file + "' has no " +
                                 (dim == 2 ? "edge" : "face") +
                                 " on the boundary"));
        }
      for (const auto &[key, id] : boundary_id)
        {
          AssertThrow(n_elements_of_face.count(key) != 0,
                      ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                 "': " + face_name(key) + " of boundary id " +
                                 std::to_string(id) + " is no face of a " +
                                 (dim == 2 ? "plane" : "solid") + " element"));
          AssertThrow(n_elements_of_face[key] == 1,
                      ExcMessage("Mesh/Abaqus boundary sets: '" + file +
                                 "': " + face_name(key) + " of boundary id " +
                                 std::to_string(id) +
                                 " lies between two elements"));
          std::vector<unsigned int> vertices;
          for (const long long node : face_of_key[key])
            vertices.push_back(vertex_of_node[node]);
          if constexpr (dim == 2)
            add_boundary_line(mesh, vertices[0], vertices[1], id);
          else
            add_boundary_face(mesh, vertices, id);
        }
      GridTools::delete_unused_vertices(mesh.vertices,
                                        mesh.cells,
                                        mesh.subcells);
      return mesh;
    }

    template Description<2>
    read_abaqus(const std::string &,
                const std::map<std::string, unsigned int> &,
                const std::map<std::string, unsigned int> &);
    template Description<3>
    read_abaqus(const std::string &,
                const std::map<std::string, unsigned int> &,
                const std::map<std::string, unsigned int> &);
  } // namespace mesh_readers
} // namespace knee_contact
