#include <knee_contact/base/input.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/elements.h>

#include <deal.II/base/mpi.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/numerics/vector_tools.h>

#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace knee_contact
{
  template <int dim>
  void
  BoundaryConditions<dim>::add_parameters(ParameterHandler  &prm,
                                          const unsigned int n_subsections)
  {
    prm.enter_subsection("Boundary conditions");
    prm.add_parameter("Number of conditions",
                      n_conditions,
                      "How many subsections 'Condition 0', 'Condition 1', "
                      "... follow. Boundaries without a condition are free "
                      "(P = 0).",
                      Patterns::Integer(0, 255));
    // Bound by reference: the vector is sized once, before binding.
    entries.clear();
    entries.resize(n_subsections);
    for (unsigned int c = 0; c < n_subsections; ++c)
      {
        Entry &entry = entries[c];
        prm.enter_subsection("Condition " + std::to_string(c));
        prm.add_parameter("Boundary ids",
                          entry.ids,
                          "Boundary ids (Gmsh: tags of physical curves in "
                          "2D, physical surfaces in 3D) this condition "
                          "applies to.",
                          Patterns::List(Patterns::Integer(0, 254)));
        input::add_selection(
          prm,
          "Type",
          entry.type,
          {{"displacement", BoundaryType::displacement},
           {"traction", BoundaryType::traction},
           {"pressure", BoundaryType::pressure},
           {"sliding", BoundaryType::sliding}},
          "displacement: u = u0 on Gamma_u; traction: tau.n = P on "
          "Gamma_tau; pressure: tau.n = -p n (p > 0 pushes into the body); "
          "sliding: u.n = 0 and zero tangential traction on Gamma_o.");
        prm.add_parameter("Components",
                          entry.components,
                          "For displacement: the components of u0 that are "
                          "prescribed; the others stay free.",
                          Patterns::List(Patterns::Selection(
                                           dim == 2 ? "x|y" : "x|y|z"),
                                         0,
                                         dim));
        prm.add_parameter("Value",
                          entry.value,
                          "Expression in x, y [m]: u0 = (u_x; u_y) [m] for "
                          "displacement, P = (P_x; P_y) [Pa] for traction, "
                          "p [Pa] for pressure; unused for sliding. In 3D "
                          "three components in x, y, z.",
                          input::expression_pattern(3));
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }



  template <int dim>
  void
  BoundaryConditions<dim>::check_parameters()
  {
    std::map<types::boundary_id, std::string> used;
    for (unsigned int c = 0; c < entries.size(); ++c)
      {
        const Entry           &entry = entries[c];
        BoundaryCondition<dim> condition;
        condition.name = "Boundary conditions/Condition " + std::to_string(c);
        condition.type = entry.type;
        for (const unsigned int id : entry.ids)
          {
            const auto b = static_cast<types::boundary_id>(id);
            AssertThrow(used.find(b) == used.end(),
                        ExcMessage(condition.name +
                                   "/Boundary ids: boundary "
                                   "id " +
                                   std::to_string(id) +
                                   " already has a condition in " + used[b]));
            used[b] = condition.name;
            condition.ids.insert(b);
          }
        AssertThrow(!condition.ids.empty(),
                    ExcMessage(condition.name + "/Boundary ids: empty list"));
        std::vector<bool> selected(dim);
        for (const auto &component : entry.components)
          selected[component[0] - 'x'] = true;
        condition.mask = ComponentMask(selected);
        AssertThrow(condition.type != BoundaryType::displacement ||
                      condition.mask.n_selected_components() > 0,
                    ExcMessage(condition.name +
                               "/Components: no component selected"));
        if (condition.type != BoundaryType::sliding)
          {
            condition.function = input::parse_expression<dim>(
              entry.value,
              condition.type == BoundaryType::pressure ? 1 : dim,
              condition.name + "/Value",
              "",
              condition.type != BoundaryType::displacement);
            condition.constant = input::numbers_only(entry.value);
          }
        list.push_back(std::move(condition));
      }
  }



  template <int dim>
  void
  BoundaryConditions<dim>::check_mesh(
    const Triangulation<dim> &triangulation) const
  {
    const auto ids = triangulation.get_boundary_ids();
    for (const auto &condition : list)
      for (const auto id : condition.ids)
        AssertThrow(std::find(ids.begin(), ids.end(), id) != ids.end(),
                    ExcMessage(condition.name +
                               "/Boundary ids: the mesh has "
                               "no boundary id " +
                               std::to_string(id)));
  }



  namespace
  {
    /**
     * u.n = 0 on the sliding boundary @p ids of a 3D mesh (linear elements:
     * vertex dofs only). Written by hand because deal.II 9.4's
     * compute_no_normal_flux_constraints() assumes that a cell at an edge
     * or corner of the boundary has a face on each side of it (true of
     * structured hexahedra): on tetrahedra, and on hexahedra made of them
     * or of an unstructured mesher's, a cell often touches an edge with
     * one face, the normals of the two sides are then averaged and only
     * their mean direction constrained (measured: a block sliding on three
     * planes off by 20 % with tetrahedra, 19 % with tetrahedra split into
     * hexahedra), and its normal vector of a triangle is computed as of a
     * quadrilateral. Hanging vertices get lines here too, which the
     * hanging-node constraints made before override. Here the normals at a
     * vertex are grouped into surfaces: faces of one boundary id whose normals
     * are within 45 degrees of the group's mean are one (smooth) surface, other
     * ids and sharper angles are others; one surface constrains u.n = 0, two
     * constrain u to their edge's direction, three or more fix u.
     */
    void
    sliding_constraints_3d(const DoFHandler<3>                &dof_handler,
                           const std::set<types::boundary_id> &ids,
                           AffineConstraints<double>          &constraints)
    {
      struct Surface
      {
        types::boundary_id id;
        Tensor<1, 3>       sum; // of the unit normals
      };
      // Per vertex: its dofs and the surfaces of its sliding faces.
      std::map<
        unsigned int,
        std::pair<std::array<types::global_dof_index, 3>, std::vector<Surface>>>
        vertices;
      for (const auto &cell : dof_handler.active_cell_iterators())
        for (const auto f : cell->face_indices())
          {
            const auto face = cell->face(f);
            if (!face->at_boundary() || ids.count(face->boundary_id()) == 0)
              continue;
            // The plane of a triangle; of a quadrilateral the plane of its
            // diagonals (flat faces of these meshes).
            Tensor<1, 3> normal =
              face->n_vertices() == 3
                ? cross_product_3d(face->vertex(1) - face->vertex(0),
                                   face->vertex(2) - face->vertex(0))
                : cross_product_3d(face->vertex(3) - face->vertex(0),
                                   face->vertex(2) - face->vertex(1));
            normal /= normal.norm();
            if (normal * (face->center() - cell->center()) < 0)
              normal *= -1;
            for (const auto v : face->vertex_indices())
              {
                auto &[dofs, surfaces] = vertices[face->vertex_index(v)];
                for (unsigned int d = 0; d < 3; ++d)
                  dofs[d] = face->vertex_dof_index(v, d);
                bool found = false;
                for (auto &surface : surfaces)
                  if (surface.id == face->boundary_id() &&
                      normal * surface.sum >=
                        std::cos(numbers::PI / 4) * surface.sum.norm())
                    {
                      surface.sum += normal;
                      found = true;
                      break;
                    }
                if (!found)
                  surfaces.push_back({face->boundary_id(), normal});
              }
          }
      for (const auto &[vertex, dofs_and_surfaces] : vertices)
        {
          const auto &[dofs, surfaces] = dofs_and_surfaces;
          // An orthonormal basis of the surfaces' normals.
          std::vector<Tensor<1, 3>> basis;
          for (const auto &surface : surfaces)
            {
              Tensor<1, 3> n = surface.sum / surface.sum.norm();
              for (const auto &b : basis)
                n -= (n * b) * b;
              if (n.norm() > 1e-6)
                basis.push_back(n / n.norm());
            }
          const auto largest = [](const Tensor<1, 3> &t) {
            unsigned int d = 0;
            for (unsigned int e = 1; e < 3; ++e)
              if (std::abs(t[e]) > std::abs(t[d]))
                d = e;
            return d;
          };
          if (basis.size() == 1)
            {
              // n . u = 0: the component of the largest |n_d| follows.
              const Tensor<1, 3> &n = basis[0];
              const unsigned int  d = largest(n);
              constraints.add_line(dofs[d]);
              for (unsigned int e = 0; e < 3; ++e)
                if (e != d && n[e] != 0)
                  constraints.add_entry(dofs[d], dofs[e], -n[e] / n[d]);
            }
          else if (basis.size() == 2)
            {
              // u along the edge t: the other components follow u_d.
              const Tensor<1, 3> t = cross_product_3d(basis[0], basis[1]);
              const unsigned int d = largest(t);
              for (unsigned int e = 0; e < 3; ++e)
                if (e != d)
                  {
                    constraints.add_line(dofs[e]);
                    if (t[e] != 0)
                      constraints.add_entry(dofs[e], dofs[d], t[e] / t[d]);
                  }
            }
          else
            for (unsigned int d = 0; d < 3; ++d)
              constraints.add_line(dofs[d]);
        }
    }
  } // namespace



  template <int dim>
  void
  BoundaryConditions<dim>::make_constraints(
    const DoFHandler<dim>     &dof_handler,
    AffineConstraints<double> &constraints) const
  {
    // Hanging nodes of adaptive refinement first. In 2D they never lie on
    // the boundary; in 3D they can, and the boundary values below are then
    // left out for them (AffineConstraints keeps the first constraint of a
    // dof), so that the hanging node follows its parents, which carry the
    // boundary values.
    constraints.clear();
    DoFTools::make_hanging_node_constraints(dof_handler, constraints);
    for (const auto &condition : list)
      if (condition.type == BoundaryType::displacement)
        for (const auto id : condition.ids)
          VectorTools::interpolate_boundary_values(elements::mapping(
                                                     dof_handler),
                                                   dof_handler,
                                                   id,
                                                   *condition.function,
                                                   constraints,
                                                   condition.mask);

    std::set<types::boundary_id> sliding;
    for (const auto &condition : list)
      if (condition.type == BoundaryType::sliding)
        sliding.insert(condition.ids.begin(), condition.ids.end());
    if (!sliding.empty())
      {
        AffineConstraints<double> sliding_constraints;
        if constexpr (dim == 3)
          sliding_constraints_3d(dof_handler, sliding, sliding_constraints);
        else
          VectorTools::compute_no_normal_flux_constraints(dof_handler,
                                                          0,
                                                          sliding,
                                                          sliding_constraints,
                                                          elements::mapping(
                                                            dof_handler));
        sliding_constraints.close();
        constraints.merge(
          sliding_constraints,
          AffineConstraints<double>::MergeConflictBehavior::left_object_wins);
      }
    // A whole mesh (a serial Triangulation, MPI perhaps not initialised)
    // has every line already.
    if (dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
          &dof_handler.get_triangulation()) != nullptr)
      {
        const MPI_Comm comm =
          dof_handler.get_triangulation().get_communicator();
        // The lines of this rank's dofs, flattened to doubles (indices are
        // below 2^53) for one all-gather: index, inhomogeneity, entries.
        const IndexSet     &owned = dof_handler.locally_owned_dofs();
        std::vector<double> mine;
        for (const auto &line : constraints.get_lines())
          if (owned.is_element(line.index))
            {
              mine.push_back(line.index);
              mine.push_back(line.inhomogeneity);
              mine.push_back(line.entries.size());
              for (const auto &[j, c] : line.entries)
                {
                  mine.push_back(j);
                  mine.push_back(c);
                }
            }
        constraints.clear();
        const std::vector<double> all =
          parallel::gather_on_every_rank(comm, mine);
        for (std::size_t at = 0; at < all.size();)
          {
            const auto i = static_cast<types::global_dof_index>(all[at]);
            constraints.add_line(i);
            constraints.set_inhomogeneity(i, all[at + 1]);
            const std::size_t n = all[at + 2];
            at += 3;
            for (std::size_t k = 0; k < n; ++k, at += 2)
              constraints.add_entry(
                i, static_cast<types::global_dof_index>(all[at]), all[at + 1]);
          }
      }
    constraints.close();
  }


  template <int dim>
  void
  BoundaryConditions<dim>::set_load_parameter(const double t)
  {
    for (auto &condition : list)
      if (condition.type == BoundaryType::traction ||
          condition.type == BoundaryType::pressure)
        condition.function->set_time(t);
  }


  template struct BoundaryCondition<2>;
  template struct BoundaryCondition<3>;
  template class BoundaryConditions<2>;
  template class BoundaryConditions<3>;
} // namespace knee_contact
