#include <knee_contact/base/input.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/contact/contact_sides.h>
#include <knee_contact/contact/face_geometry.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/vector.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

namespace knee_contact
{
  std::string
  csv_file_name(const std::string &interface_name)
  {
    std::string name = interface_name;
    std::replace_if(
      name.begin(),
      name.end(),
      [](const char c) {
        return !std::isalnum(static_cast<unsigned char>(c)) && c != '-';
      },
      '_');
    return "contact_" + name + ".csv";
  }



  std::string
  pairing_name(const Pairing pairing)
  {
    switch (pairing)
      {
        case Pairing::mortar:
          return "mortar";
        case Pairing::node_to_segment:
          return "node-to-segment";
        case Pairing::node_to_node:
          return "node-to-node";
      }
    return "";
  }



  void
  ContactInterfaces::add_parameters(ParameterHandler  &prm,
                                    const unsigned int n_subsections)
  {
    prm.enter_subsection("Contact");
    prm.add_parameter("Number of interfaces",
                      n_interfaces,
                      "How many subsections 'Interface 0', 'Interface 1', "
                      "... follow (the seed's Gamma_c^kl).",
                      Patterns::Integer(0, 255));
    // Bound by reference: the vector is sized once, before binding.
    list.clear();
    list.resize(n_subsections);
    for (unsigned int i = 0; i < n_subsections; ++i)
      {
        ContactInterface &interface = list[i];
        interface.name              = "interface " + std::to_string(i);
        prm.enter_subsection("Interface " + std::to_string(i));
        prm.add_parameter("Name",
                          interface.name,
                          "Name used in results and file names.");
        prm.add_parameter("Slave boundary id",
                          interface.slave_id,
                          "Boundary id of the side of body k whose vertices "
                          "are paired (prefer the finer or softer side).",
                          Patterns::Integer(0, 254));
        prm.add_parameter("Master boundary id",
                          interface.master_id,
                          "Boundary id of the side of body l.",
                          Patterns::Integer(0, 254));
        std::vector<std::pair<std::string, Pairing>> pairings;
        for (const Pairing p :
             {Pairing::mortar, Pairing::node_to_segment, Pairing::node_to_node})
          pairings.emplace_back(pairing_name(p), p);
        input::add_selection(
          prm,
          "Pairing",
          interface.pairing,
          pairings,
          "mortar: dual mortar (segment-to-segment) conditions, one per "
          "slave vertex, weighted by the biorthogonal multiplier basis; "
          "exact contact pressure for the patch test on non-matching "
          "meshes, either side slave. node-to-segment: each slave vertex is "
          "paired with the point of the master side along its normal. "
          "node-to-node: the seed's node pairs, every slave vertex must "
          "coincide with a master vertex.");
        prm.add_parameter("Maximum gap",
                          interface.maximum_gap,
                          "Slave vertices farther than this from the master "
                          "side [m] are not paired; 0: no limit.",
                          Patterns::Double(0));
        input::add_selection(
          prm,
          "Friction",
          interface.friction,
          {{"none", Friction::none},
           {"tresca", Friction::tresca},
           {"coulomb", Friction::coulomb}},
          "none: frictionless (zero tangential traction). coulomb: the "
          "tangential traction is at most 'Friction coefficient' times the "
          "contact pressure; the pair sticks below it and slips at it. "
          "tresca: the same with the fixed bound 'Tresca bound'. 2D; the "
          "scene is loaded in one step from the unloaded state.");
        prm.add_parameter("Friction coefficient",
                          interface.friction_coefficient,
                          "mu >= 0 of Friction = coulomb.",
                          Patterns::Double(0));
        prm.add_parameter("Tresca bound",
                          interface.tresca_bound,
                          "The slip bound [Pa] of Friction = tresca.",
                          Patterns::Double(0));
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }



  void
  ContactInterfaces::check_parameters() const
  {
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const ContactInterface &interface = list[i];
        input::check_name(interface.name,
                          "Contact/Interface " + std::to_string(i) + "/Name");
        const std::string where =
          "Contact/Interface " + std::to_string(i) + ": ";
        AssertThrow(std::isfinite(interface.friction_coefficient) &&
                      std::isfinite(interface.tresca_bound),
                    ExcMessage(where + "Friction coefficient and Tresca "
                                       "bound must be finite"));
        AssertThrow(interface.slave_id != interface.master_id,
                    ExcMessage(where +
                               "slave and master boundary ids are "
                               "both " +
                               std::to_string(interface.slave_id)));
        for (unsigned int j = 0; j < i; ++j)
          {
            const ContactInterface &other = list[j];
            AssertThrow(other.name != interface.name &&
                          csv_file_name(other.name) !=
                            csv_file_name(interface.name),
                        ExcMessage(where + "the name '" + interface.name +
                                   "' is (as a file name, " +
                                   csv_file_name(interface.name) +
                                   ") that of interface '" + other.name +
                                   "' too"));
            AssertThrow(other.slave_id != interface.slave_id &&
                          other.slave_id != interface.master_id &&
                          other.master_id != interface.slave_id &&
                          other.master_id != interface.master_id,
                        ExcMessage(where +
                                   "shares a boundary id with "
                                   "interface '" +
                                   other.name + "'"));
          }
      }
  }



  template <int dim>
  void
  ContactInterfaces::check_mesh(const Triangulation<dim>        &triangulation,
                                const std::vector<unsigned int> &body_ids) const
  {
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        std::set<unsigned int> slave_bodies, master_bodies;
        for (const auto &cell : triangulation.active_cell_iterators())
          for (const auto &face : cell->face_iterators())
            if (face->at_boundary())
              {
                if (face->boundary_id() == list[i].slave_id)
                  slave_bodies.insert(body_ids[cell->active_cell_index()]);
                if (face->boundary_id() == list[i].master_id)
                  master_bodies.insert(body_ids[cell->active_cell_index()]);
              }
        const std::string where = "Contact/Interface " + std::to_string(i) +
                                  " ('" + list[i].name + "'): ";
        AssertThrow(!slave_bodies.empty(),
                    ExcMessage(where + "the mesh has no boundary id " +
                               std::to_string(list[i].slave_id)));
        AssertThrow(!master_bodies.empty(),
                    ExcMessage(where + "the mesh has no boundary id " +
                               std::to_string(list[i].master_id)));
        for (const unsigned int b : slave_bodies)
          AssertThrow(master_bodies.count(b) == 0,
                      ExcMessage(where +
                                 "slave and master sides both lie "
                                 "on body " +
                                 std::to_string(b) +
                                 " (self contact is not supported; bodies "
                                 "sharing vertices are bonded)"));
      }
  }



  namespace
  {
    // Outward normal of a boundary face of a cell, with the face's measure
    // (length in 2D, area in 3D) as its norm, so that summing over a
    // vertex's faces weights by measure. 3D: the cross product of the
    // diagonals (a quadrilateral's 0-3 and 1-2), which is the normal at
    // the centre of a bilinear face with the area of a flat one.
    template <int dim>
    Tensor<1, dim>
    outward_normal(const typename DoFHandler<dim>::active_cell_iterator &cell,
                   const unsigned int                                    f)
    {
      const auto     face = cell->face(f);
      Tensor<1, dim> n;
      if constexpr (dim == 2)
        {
          const Tensor<1, 2> t = face->vertex(1) - face->vertex(0);
          n                    = Tensor<1, 2>({t[1], -t[0]});
        }
      else if (face->n_vertices() == 3)
        n = 0.5 * cross_product_3d(face->vertex(1) - face->vertex(0),
                                   face->vertex(2) - face->vertex(0));
      else
        n = 0.5 * cross_product_3d(face->vertex(3) - face->vertex(0),
                                   face->vertex(2) - face->vertex(1));
      if (n * (face->center() - cell->center()) < 0)
        n = -n;
      return n;
    }

    // Substitute the Gamma_u/Gamma_o lines into a row: x_i = sum_j c_ij x_j
    // + g_i for every constrained i, so the row acts on free dofs only.
    void
    reduce_row(ContactRow &pair, const AffineConstraints<double> &constraints)
    {
      std::map<types::global_dof_index, double> reduced;
      double                                    rhs = pair.gap;
      for (const auto &[dof, a] : pair.row)
        if (constraints.is_constrained(dof))
          {
            rhs -= a * constraints.get_inhomogeneity(dof);
            for (const auto &[j, c] : *constraints.get_constraint_entries(dof))
              reduced[j] += a * c;
          }
        else
          reduced[dof] += a;
      double scale = 0;
      for (const auto &entry : reduced)
        scale = std::max(scale, std::abs(entry.second));
      pair.reduced_row.clear();
      for (const auto &entry : reduced)
        if (std::abs(entry.second) > 1e-12 * scale)
          pair.reduced_row.push_back(entry);
      pair.reduced_gap = rhs;
    }

    // Whether every line of the constrained ones among a vertex's dofs
    // refers to that vertex's dofs only (Gamma_u, or Gamma_o on a plane
    // through it), not to other vertices (a hanging node).
    template <std::size_t n>
    bool
    held_by_conditions(const std::array<types::global_dof_index, n> &dofs,
                       const AffineConstraints<double> &constraints)
    {
      for (const auto dof : dofs)
        if (constraints.is_constrained(dof))
          for (const auto &entry : *constraints.get_constraint_entries(dof))
            if (std::find(dofs.begin(), dofs.end(), entry.first) == dofs.end())
              return false;
      return true;
    }

    /**
     * A distributed mesh's sides: every rank's faces (those of the cells
     * it owns) on every rank, rank by rank, and the slave vertices' sums
     * (normal, weight) over the ranks' faces. Flattened to doubles for
     * one deal.II all-gather (indices, keys and counts are below 2^53);
     * written here because the sides are this program's own structure.
     */
    template <int dim>
    void
    gather_sides(ContactSides<dim> &sides, const MPI_Comm comm)
    {
      using Face = typename ContactSides<dim>::Face;
      std::vector<double> mine;
      const auto          put_face = [&](const Face &face) {
        mine.push_back(face.n_vertices);
        for (unsigned int v = 0; v < Face::max_vertices; ++v)
          {
            mine.push_back(face.vertex_keys[v]);
            for (unsigned int d = 0; d < dim; ++d)
              {
                mine.push_back(face.vertices[v][d]);
                mine.push_back(face.dofs[v][d]);
              }
          }
        for (unsigned int d = 0; d < dim; ++d)
          mine.push_back(face.normal[d]);
        mine.push_back(face.measure);
        mine.push_back(face.diameter);
      };
      mine.push_back(sides.slaves.size());
      for (const auto &[key, slave] : sides.slaves)
        {
          mine.push_back(key);
          for (unsigned int d = 0; d < dim; ++d)
            {
              mine.push_back(slave.position[d]);
              mine.push_back(slave.normal[d]);
              mine.push_back(slave.dofs[d]);
            }
          mine.push_back(slave.length);
        }
      for (const auto *faces : {&sides.slave_faces, &sides.master_faces})
        {
          mine.push_back(faces->size());
          for (const Face &face : *faces)
            put_face(face);
        }

      ContactSides<dim> all;
      all.min_length = std::numeric_limits<double>::max();
      // Each rank's block: its slaves, slave faces and master faces, each
      // after its count.
      const std::vector<double> theirs =
        parallel::gather_on_every_rank(comm, mine);
      std::size_t at = 0;
      while (at < theirs.size())
        {
          const auto next  = [&]() { return theirs.at(at++); };
          const auto index = [&]() {
            return static_cast<types::global_dof_index>(next());
          };
          for (std::size_t n = index(); n > 0; --n)
            {
              auto &slave = all.slaves[static_cast<unsigned int>(next())];
              for (unsigned int d = 0; d < dim; ++d)
                {
                  slave.position[d] = next();
                  slave.normal[d] += next();
                  slave.dofs[d] = index();
                }
              slave.length += next();
            }
          for (auto *faces : {&all.slave_faces, &all.master_faces})
            for (std::size_t n = index(); n > 0; --n)
              {
                Face face;
                face.n_vertices = index();
                for (unsigned int v = 0; v < Face::max_vertices; ++v)
                  {
                    face.vertex_keys[v] = index();
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        face.vertices[v][d] = next();
                        face.dofs[v][d]     = index();
                      }
                  }
                for (unsigned int d = 0; d < dim; ++d)
                  face.normal[d] = next();
                face.measure  = next();
                face.diameter = next();
                if (faces == &all.slave_faces)
                  all.min_length =
                    std::min(all.min_length,
                             dim == 2 ? face.measure : face.diameter);
                faces->push_back(face);
              }
        }
      sides = std::move(all);
    }

    // Faces that are neither segments, triangles nor quadrilaterals cannot
    // occur in deal.II's meshes; 3D faces carry 3 or 4 vertices.
    template <int dim>
    ContactSides<dim>
    collect_sides(const DoFHandler<dim>           &dof_handler,
                  const ContactInterface          &interface,
                  const AffineConstraints<double> &constraints,
                  const std::vector<unsigned int> *vertex_id)
    {
      using Face = typename ContactSides<dim>::Face;
      ContactSides<dim> sides;
      sides.min_length = std::numeric_limits<double>::max();
      // A distributed mesh's ghosts are their owners' to collect.
      for (const auto &cell : dof_handler.active_cell_iterators())
        for (const unsigned int f : cell->face_indices())
          if (cell->is_locally_owned() && cell->face(f)->at_boundary() &&
              (cell->face(f)->boundary_id() == interface.slave_id ||
               cell->face(f)->boundary_id() == interface.master_id))
            {
              const auto           face = cell->face(f);
              const Tensor<1, dim> n    = outward_normal<dim>(cell, f);
              Face                 side;
              side.n_vertices = face->n_vertices();
              AssertThrow(side.n_vertices <= Face::max_vertices,
                          ExcInternalError());
              for (unsigned int v = 0; v < side.n_vertices; ++v)
                {
                  side.vertex_keys[v] = vertex_id != nullptr
                                          ? vertex_id->at(face->vertex_index(v))
                                          : face->vertex_index(v);
                  AssertThrow(side.vertex_keys[v] !=
                                numbers::invalid_unsigned_int,
                              ExcMessage("Contact: a vertex of a refined "
                                         "distributed mesh has no whole "
                                         "index (distribute the mesh made "
                                         "whole at its refinement)"));
                  side.vertices[v] = face->vertex(v);
                  for (unsigned int d = 0; d < dim; ++d)
                    side.dofs[v][d] = face->vertex_dof_index(v, d);
                }
              side.normal  = n / n.norm();
              side.measure = n.norm();
              for (unsigned int v = 0; v < side.n_vertices; ++v)
                for (unsigned int w = v + 1; w < side.n_vertices; ++w)
                  side.diameter =
                    std::max(side.diameter,
                             side.vertices[v].distance(side.vertices[w]));
              if (face->boundary_id() == interface.slave_id)
                {
                  for (unsigned int v = 0; v < side.n_vertices; ++v)
                    {
                      auto &s    = sides.slaves[side.vertex_keys[v]];
                      s.position = side.vertices[v];
                      s.normal += n; // measure-weighted: |n| = measure
                      if constexpr (dim == 2)
                        s.length += 0.5 * n.norm();
                      else
                        s.length += n.norm() / side.n_vertices;
                      s.dofs = side.dofs[v];
                    }
                  sides.min_length =
                    std::min(sides.min_length,
                             dim == 2 ? n.norm() : side.diameter);
                  sides.slave_faces.push_back(side);
                }
              else
                sides.master_faces.push_back(side);
            }
      if (vertex_id != nullptr)
        gather_sides(sides, dof_handler.get_triangulation().get_communicator());
      // 3D: hanging slave vertices, their x component's line referring to
      // the x components of other slave vertices only.
      if constexpr (dim == 3)
        {
          std::map<types::global_dof_index, unsigned int> vertex_of_x_dof;
          for (const auto &[key, vertex] : sides.slaves)
            vertex_of_x_dof[vertex.dofs[0]] = key;
          for (auto &[key, vertex] : sides.slaves)
            if (constraints.is_constrained(vertex.dofs[0]))
              {
                std::vector<std::pair<unsigned int, double>> parents;
                for (const auto &[dof, c] :
                     *constraints.get_constraint_entries(vertex.dofs[0]))
                  {
                    const auto parent = vertex_of_x_dof.find(dof);
                    if (parent == vertex_of_x_dof.end())
                      {
                        parents.clear();
                        break;
                      }
                    parents.emplace_back(parent->second, c);
                  }
                vertex.parents = std::move(parents);
              }
        }
      return sides;
    }
  } // namespace



  template <int dim>
  ContactPairs<dim>
  ContactInterfaces::make_pairs(
    const DoFHandler<dim>           &dof_handler,
    const AffineConstraints<double> &constraints,
    const std::vector<unsigned int> *vertex_id) const
  {
    ContactPairs<dim>                 pairs;
    std::set<types::global_dof_index> eliminated;
    // The dofs of the rows that eliminate a master dof (rows of slave
    // vertices that Gamma_u/Gamma_o hold along the normal). A master dof a
    // later such row eliminates must not appear in an earlier one: then
    // each refers only to dofs eliminated before it and no set of active
    // rows forms a cycle of constraints. (2D has such a row at a held
    // corner; 3D along a held edge, neighbours sharing master dofs.) Rows
    // that eliminate their own slave dof refer to no other slave dof.
    std::set<types::global_dof_index> in_master_rows;
    const bool                        friction =
      std::any_of(list.begin(), list.end(), [](const ContactInterface &i) {
        return i.friction != Friction::none;
      });
    for (unsigned int i = 0; i < list.size(); ++i)
      {
        const ContactInterface &interface = list[i];
        const ContactSides<dim> sides =
          collect_sides<dim>(dof_handler, interface, constraints, vertex_id);
        const std::string where = "Contact/Interface " + std::to_string(i) +
                                  " ('" + interface.name + "'): ";
        AssertThrow(!sides.slaves.empty() && !sides.master_faces.empty(),
                    ExcMessage(where + "a side has no faces"));
        // The master faces by place, for the common normals of 3D
        // frictional rows.
        std::optional<ContactSearch<dim>> search;
        if (dim == 3 && friction)
          search.emplace(master_face_search(sides));
        ContactPairs<dim> rows =
          interface.pairing == Pairing::mortar
            ? mortar_rows<dim>(sides, interface, i, where)
            : node_to_segment_rows<dim>(sides, interface, i, where);

        for (unsigned int p = 0; p < rows.size(); ++p)
          {
            ContactRow &pair       = rows.rows[p];
            const auto &slave_dofs = rows.points[p].slave_dofs;
            // The frictional rows, built from the normal row, which lists
            // each vertex's (x, y[, z]) entries w n_x, w n_y[, w n_z] in
            // turn: the tangential rows with w t_j in their place
            // (ContactPoint::tangents) and the stick rows with w e_k.
            const Tensor<1, dim> &n             = rows.points[p].normal;
            auto                 &t             = rows.points[p].tangents;
            const auto            weighted_rows = [&](const auto &direction) {
              ContactRow made;
              made.interface = pair.interface;
              made.length    = pair.length;
              for (std::size_t k = 0; k + dim - 1 < pair.row.size(); k += dim)
                {
                  double w = 0;
                  for (unsigned int d = 0; d < dim; ++d)
                    w += pair.row[k + d].second * n[d];
                  for (unsigned int d = 0; d < dim; ++d)
                    made.row.emplace_back(pair.row[k + d].first,
                                          w * direction[d]);
                }
              return made;
            };
            if (friction)
              {
                if constexpr (dim == 2)
                  {
                    const MasterHit<2> hit = master_along_normal(
                      sides, rows.points[p].position, n, pair.length);
                    Tensor<1, 2> m = n;
                    if (hit.face != nullptr)
                      m -= hit.face->normal;
                    m /= m.norm();
                    t[0][0] = -m[1];
                    t[0][1] = m[0];
                  }
                else
                  {
                    // The common normal m = n - n_master (the master's
                    // normal where n meets it, else n alone), as in 2D;
                    // two orthonormal tangents of it, the first along the
                    // axis least along m.
                    const MasterHit<3> hit =
                      master_along_normal(sides,
                                          *search,
                                          rows.points[p].position,
                                          n,
                                          pair.spacing(dim),
                                          interface.maximum_gap);
                    Tensor<1, dim> m = n;
                    if (hit.face != nullptr)
                      {
                        const auto d =
                          face_geometry::tangents(*hit.face, hit.xi);
                        Tensor<1, dim> n_master = cross_product_3d(d[0], d[1]);
                        if (n_master * hit.face->normal < 0)
                          n_master *= -1;
                        m -= n_master / n_master.norm();
                      }
                    m /= m.norm();
                    unsigned int least = 0;
                    for (unsigned int d = 1; d < dim; ++d)
                      if (std::abs(m[d]) < std::abs(m[least]))
                        least = d;
                    Tensor<1, dim> e;
                    e[least] = 1;
                    t[0]     = e - (e * m) * m;
                    t[0] /= t[0].norm();
                    t[1] = cross_product_3d(m, t[0]);
                  }
              }
            // Eliminate the free slave component with the largest
            // coefficient, else the largest free other component. A normal
            // row (@p normal) eliminates no master dof of an earlier normal
            // row; a frictional pair's tangential row is never active with
            // its normal row and is exempt (it may eliminate another dof of
            // the same master face).
            const auto choose = [&](ContactRow &row, const bool normal) {
              reduce_row(row, constraints);
              // Pass 0: the slave side. Pass 1: the other dofs, for a
              // normal row none that an earlier master row refers to.
              // Pass 2 (normal rows where pass 1 found none): any free dof.
              // That is a slave vertex hanging on a refined neighbour's
              // edge or face, whose row refers to its parents' dofs (as
              // before, the active-set loop finds a cycle if one forms);
              // a slave vertex that Gamma_u/Gamma_o hold (its lines refer
              // to its own dofs only) would eliminate master dofs in terms
              // of those its held neighbours eliminate, a cycle no set of
              // constraint lines can hold: refused. A coefficient of 1e-12
              // or less is round-off, no dof to eliminate.
              for (const unsigned int pass : {0, 1, 2})
                {
                  if (pass == 2 && !normal)
                    break;
                  double largest = 0;
                  for (const auto &[dof, a] : row.reduced_row)
                    {
                      const bool on_slave =
                        std::find(slave_dofs.begin(), slave_dofs.end(), dof) !=
                        slave_dofs.end();
                      if ((pass == 2 || on_slave == (pass == 0)) &&
                          !eliminated.count(dof) &&
                          (pass != 1 || !normal ||
                           !in_master_rows.count(dof)) &&
                          std::abs(a) > largest + 1e-12)
                        {
                          largest        = std::abs(a);
                          row.eliminated = dof;
                        }
                    }
                  if (row.eliminated == numbers::invalid_dof_index)
                    continue;
                  row.slave_eliminated = pass == 0;
                  if (pass == 2)
                    AssertThrow(!held_by_conditions(slave_dofs, constraints),
                                ExcMessage(
                                  where + "the slave vertex at " +
                                  point_text(rows.points[p].position) +
                                  " is held along its normal by the boundary "
                                  "conditions, and so are its neighbours: "
                                  "their contact rows constrain the same "
                                  "master dofs and cannot all be held (make "
                                  "the other side the slave, or leave the "
                                  "slave side free along the contact normal)"));
                  break;
                }
              if (row.eliminated != numbers::invalid_dof_index)
                eliminated.insert(row.eliminated);
              if (normal && !row.slave_eliminated)
                for (const auto &entry : row.reduced_row)
                  in_master_rows.insert(entry.first);
            };
            choose(pair, true);
            if (friction)
              {
                for (unsigned int j = 0; j + 1 < dim; ++j)
                  {
                    ContactRow slide = weighted_rows(t[j]);
                    choose(slide, false);
                    slide.measured_only = true;
                    pairs.tangential[j].push_back(std::move(slide));
                  }
                // A sticking pair holds N and every T_j; as rows they would
                // eliminate the slave's components in terms of each other (a
                // cycle of constraints) wherever n is not along an axis. So
                // it is held by the rows S_k of the weighted jump's
                // components instead, each eliminating a slave component of
                // its own (never active together with the pair's N or T
                // rows: they may eliminate the same dofs). Their gaps follow
                // from those of N and T (stick_coefficients()).
                const StickCoefficients c = stick_coefficients<dim>(n, t);
                std::set<types::global_dof_index> taken;
                for (unsigned int k = 0; k < dim; ++k)
                  {
                    Tensor<1, dim> e;
                    e[k]                 = 1;
                    ContactRow component = weighted_rows(e);
                    component.gap        = c[k][0] * pair.gap;
                    component.stick      = true;
                    reduce_row(component, constraints);
                    double largest = 0;
                    for (const auto &[dof, a] : component.reduced_row)
                      if (std::find(slave_dofs.begin(),
                                    slave_dofs.end(),
                                    dof) != slave_dofs.end() &&
                          !taken.count(dof) && std::abs(a) > largest + 1e-12)
                        {
                          largest              = std::abs(a);
                          component.eliminated = dof;
                        }
                    // No free slave component (a slave vertex on a
                    // symmetry plane that Gamma_o holds along e_k): the
                    // pair cannot stick unless the row is left with
                    // nothing (held_by_conditions()). Eliminating a master
                    // dof instead made the loop cycle on a half model of
                    // two spheres (measured): a full model is the remedy.
                    if (component.eliminated != numbers::invalid_dof_index)
                      taken.insert(component.eliminated);
                    pairs.stick[k].push_back(std::move(component));
                  }
              }
            pairs.push_back(std::move(pair), rows.points[p]);
          }
      }
    return pairs;
  }



  template ContactPairs<2>
  ContactInterfaces::make_pairs(const DoFHandler<2> &,
                                const AffineConstraints<double> &,
                                const std::vector<unsigned int> *) const;
  template ContactPairs<3>
  ContactInterfaces::make_pairs(const DoFHandler<3> &,
                                const AffineConstraints<double> &,
                                const std::vector<unsigned int> *) const;
  template void
  ContactInterfaces::check_mesh(const Triangulation<2> &,
                                const std::vector<unsigned int> &) const;
  template void
  ContactInterfaces::check_mesh(const Triangulation<3> &,
                                const std::vector<unsigned int> &) const;
} // namespace knee_contact
