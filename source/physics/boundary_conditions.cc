#include <knee_contact/core/input.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/elements.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/mapping_q1.h>
#include <deal.II/numerics/vector_tools.h>

#include <cmath>
#include <map>

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
          condition.function = input::parse_expression<dim>(
            entry.value,
            condition.type == BoundaryType::pressure ? 1 : dim,
            condition.name + "/Value",
            "",
            condition.type != BoundaryType::displacement);
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
