#include <knee_contact/base/input.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/verification.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <iomanip>

namespace knee_contact
{
  template <int dim>
  void
  Verification<dim>::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Verification");
    prm.add_parameter("Exact displacement",
                      entries.exact_displacement,
                      "Reference u = (u_x; u_y) [m] in x, y (3D: (u_x; u_y; "
                      "u_z) in x, y, z): L2, energy and nodal errors are "
                      "reported. Empty: none.",
                      input::expression_pattern(3, true));
    prm.add_parameter("Exact stress",
                      entries.exact_stress,
                      "Reference (tau_xx; tau_yy; tau_xy) [Pa] (3D: (tau_xx; "
                      "tau_yy; tau_zz; tau_xy; tau_xz; tau_yz)): the maximum "
                      "error at the cells' Gauss points relative to the "
                      "largest reference stress is checked against "
                      "Tolerance. Empty: none.",
                      input::expression_pattern(6, true));
    prm.add_parameter("Exact contact pressure",
                      entries.exact_pressure,
                      "Reference contact pressure [Pa] at the slave vertices: "
                      "the maximum error relative to its largest value is "
                      "checked against Tolerance. Empty: none.",
                      input::expression_pattern(1, true));
    prm.add_parameter("Tolerance",
                      tolerance,
                      "Tolerance of the exact-field checks (relative); the "
                      "nodal displacement error is checked too when an "
                      "exact displacement is given and Minimum L2 rate is 0.",
                      Patterns::Double(0));
    prm.add_parameter("Minimum L2 rate",
                      min_l2_rate,
                      "With several refinement cycles: the smallest allowed "
                      "observed L2 rate after the first refinement (h ~ "
                      "n_dofs^-1/2); 0: no check.",
                      Patterns::Double(0));
    prm.add_parameter("Minimum energy rate",
                      min_energy_rate,
                      "The same for the energy norm error.",
                      Patterns::Double(0));
    prm.add_parameter("Maximum L2 error",
                      max_l2_error,
                      "With an exact displacement: the largest allowed "
                      "relative L2 error on the last mesh; 0: no check.",
                      Patterns::Double(0));
    prm.add_parameter("Minimum pressure rate",
                      min_pressure_rate,
                      "The same for the L2 error of the contact pressure "
                      "over the slave sides against Exact contact pressure.",
                      Patterns::Double(0));
    prm.add_parameter("Check KKT",
                      check_kkt,
                      "Check lambda >= 0, A x <= g (1e-10 of max |u|), "
                      "complementarity and equilibrium (1e-8) when the scene "
                      "has contact.");
    prm.add_parameter("Reference peak pressure",
                      entries.peak_pressure,
                      "Constant expression for the expected largest contact "
                      "pressure [Pa], e.g. a Hertz formula. Empty: none.",
                      input::expression_pattern(1, true));
    prm.add_parameter("Peak pressure tolerance",
                      peak_tolerance,
                      "Allowed relative error of the peak pressure.",
                      Patterns::Double(0));
    prm.add_parameter("Reference contact length",
                      entries.contact_length,
                      "Constant expression for the expected length of slave "
                      "boundary in contact [m], summed over interfaces. "
                      "Empty: none.",
                      input::expression_pattern(1, true));
    prm.add_parameter("Contact length tolerance",
                      length_tolerance,
                      "Allowed absolute error of the contact length [m].",
                      Patterns::Double(0));
    prm.add_parameter("Reference energy",
                      entries.reference_energy,
                      "Constant expression for a(u,u) [J/m] of an overkill "
                      "solution: its relative error is checked against "
                      "Energy tolerance. Empty: none.",
                      input::expression_pattern(1, true));
    prm.add_parameter("Energy tolerance",
                      energy_tolerance,
                      "Allowed relative error of a(u,u) against Reference "
                      "energy.",
                      Patterns::Double(0));
    prm.add_parameter(
      "Reference extreme stress_yy",
      entries.extreme_stress,
      "'material name: value' [Pa]: the extreme (most negative if the value "
      "is negative, else largest) tau_yy in that material of an overkill "
      "solution; its relative error is checked against Extreme stress "
      "tolerance. Empty: none.",
      input::named_list_pattern(Patterns::Anything()));
    prm.add_parameter("Extreme stress tolerance",
                      extreme_stress_tolerance,
                      "Allowed relative error of that extreme tau_yy.",
                      Patterns::Double(0));
    prm.add_parameter(
      "Reference contact forces",
      entries.interface_forces,
      "Expected magnitude of the contact force on each interface's slave "
      "body [N/m]: 'interface name: constant expression; ...', e.g. the load "
      "a body held only by that interface carries (with friction the normal "
      "and tangential forces together).",
      input::named_list_pattern(Patterns::Anything()));
    prm.add_parameter(
      "Reference tangential forces",
      entries.tangential_forces,
      "Expected magnitude of the friction force on each interface's slave "
      "body [N/m], as Reference contact forces, e.g. mu times the normal "
      "force where the whole interface slips.",
      input::named_list_pattern(Patterns::Anything()));
    prm.add_parameter("Contact force tolerance",
                      force_tolerance,
                      "Allowed relative error of those forces.",
                      Patterns::Double(0));
    prm.leave_subsection();
  }



  template <int dim>
  void
  Verification<dim>::check_parameters()
  {
    const auto optional = [](const std::string &text,
                             const std::string &name,
                             const unsigned int n_components) {
      return text.empty()
               ? nullptr
               : input::parse_expression<dim>(
                   text, n_components, "Verification/" + name, "", true);
    };
    exact_displacement =
      optional(entries.exact_displacement, "Exact displacement", dim);
    exact_stress =
      optional(entries.exact_stress, "Exact stress", dim == 2 ? 3 : 6);
    exact_pressure =
      optional(entries.exact_pressure, "Exact contact pressure", 1);
    if (!entries.peak_pressure.empty())
      peak_pressure =
        input::evaluate_constant(entries.peak_pressure,
                                 "Verification/Reference peak pressure");
    if (!entries.contact_length.empty())
      contact_length =
        input::evaluate_constant(entries.contact_length,
                                 "Verification/Reference contact length");
    if (!entries.reference_energy.empty())
      reference_energy =
        input::evaluate_constant(entries.reference_energy,
                                 "Verification/Reference energy");
    for (const auto &[name, value] : entries.interface_forces)
      interface_forces.emplace_back(
        name,
        input::evaluate_constant(value,
                                 "Verification/Reference contact forces"));
    for (const auto &[name, value] : entries.tangential_forces)
      tangential_forces.emplace_back(
        name,
        input::evaluate_constant(value,
                                 "Verification/Reference tangential forces"));
    // Their relative errors are checked: a reference must be positive.
    for (const auto &[forces, parameter] :
         {std::make_pair(&interface_forces, "Reference contact forces"),
          std::make_pair(&tangential_forces, "Reference tangential forces")})
      for (const auto &[name, force] : *forces)
        AssertThrow(force > 0,
                    ExcMessage("Verification/" + std::string(parameter) +
                               ": the force of '" + name +
                               "' must be positive (its relative error is "
                               "checked)"));
    AssertThrow(entries.extreme_stress.size() <= 1,
                ExcMessage("Verification/Reference extreme stress_yy: "
                           "give one material, not several"));
    for (const auto &[name, value] : entries.extreme_stress)
      {
        extreme_stress_material = name;
        extreme_stress =
          input::evaluate_constant(value,
                                   "Verification/Reference extreme stress_yy");
      }
  }



  template <int dim>
  Errors
  Verification<dim>::compute_errors(const DoFHandler<dim>   &dof_handler,
                                    const Vector<double>    &solution,
                                    const Materials<dim>    &materials,
                                    const ContactPairs<dim> &pairs,
                                    const Results<dim>      &results) const
  {
    Errors errors;
    if (exact_displacement || exact_stress)
      {
        // Errors in L2, in the energy norm a(e, e)^1/2 and of the stress at
        // Gauss points; the exact gradient comes from fourth order
        // differences of the expression.
        FEValues<dim> fe_values(elements::mapping(dof_handler),
                                dof_handler.get_fe(),
                                elements::cell_quadrature(dof_handler, 3),
                                update_values | update_gradients |
                                  update_quadrature_points | update_JxW_values);
        const FEValuesExtractors::Vector u(0);
        const unsigned int               n_q = fe_values.n_quadrature_points;
        std::vector<Tensor<1, dim>>      values(n_q);
        std::vector<SymmetricTensor<2, dim>> strains(n_q);
        std::vector<Vector<double>> exact_values(n_q, Vector<double>(dim));
        std::vector<std::vector<Tensor<1, dim>>> exact_gradients(
          n_q, std::vector<Tensor<1, dim>>(dim));
        // The components of Exact stress, in its order.
        const std::vector<std::pair<unsigned int, unsigned int>> components =
          dim == 2 ? std::vector<std::pair<unsigned int, unsigned int>>{{0, 0},
                                                                        {1, 1},
                                                                        {0, 1}}
                   : std::vector<std::pair<unsigned int, unsigned int>>{
                       {0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
        Vector<double> stress_values(components.size());
        double         l2 = 0, l2_norm = 0, energy = 0, energy_norm = 0;
        double         stress_error = 0, stress_max = 0;
        // On a distributed mesh each rank its own cells, summed and
        // maximised over the ranks below.
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              fe_values.reinit(cell);
              fe_values[u].get_function_values(solution, values);
              fe_values[u].get_function_symmetric_gradients(solution, strains);
              const Material<dim> &material = materials[cell->material_id()];
              if (exact_displacement)
                {
                  exact_displacement->vector_value_list(
                    fe_values.get_quadrature_points(), exact_values);
                  exact_displacement->vector_gradient_list(
                    fe_values.get_quadrature_points(), exact_gradients);
                }
              for (unsigned int q = 0; q < n_q; ++q)
                {
                  if (exact_displacement)
                    {
                      SymmetricTensor<2, dim> exact_strain;
                      for (unsigned int i = 0; i < dim; ++i)
                        for (unsigned int j = i; j < dim; ++j)
                          exact_strain[i][j] = 0.5 * (exact_gradients[q][i][j] +
                                                      exact_gradients[q][j][i]);
                      Tensor<1, dim> exact;
                      for (unsigned int d = 0; d < dim; ++d)
                        exact[d] = exact_values[q](d);
                      const SymmetricTensor<2, dim> e =
                        strains[q] - exact_strain;
                      l2 +=
                        (values[q] - exact).norm_square() * fe_values.JxW(q);
                      l2_norm += exact.norm_square() * fe_values.JxW(q);
                      energy += material.stress(e) * e * fe_values.JxW(q);
                      energy_norm += material.stress(exact_strain) *
                                     exact_strain * fe_values.JxW(q);
                    }
                  if (exact_stress)
                    {
                      exact_stress->vector_value(fe_values.quadrature_point(q),
                                                 stress_values);
                      const auto s = material.stress(strains[q]);
                      for (unsigned int c = 0; c < components.size(); ++c)
                        {
                          const auto [i, j] = components[c];
                          stress_error =
                            std::max(stress_error,
                                     std::abs(s[i][j] - stress_values(c)));
                          stress_max =
                            std::max(stress_max, std::abs(stress_values(c)));
                        }
                    }
                }
            }
        const bool distributed =
          dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
            &dof_handler.get_triangulation()) != nullptr;
        if (distributed)
          {
            const MPI_Comm comm = parallel::communicator();
            l2                  = Utilities::MPI::sum(l2, comm);
            l2_norm             = Utilities::MPI::sum(l2_norm, comm);
            energy              = Utilities::MPI::sum(energy, comm);
            energy_norm         = Utilities::MPI::sum(energy_norm, comm);
            stress_error        = Utilities::MPI::max(stress_error, comm);
            stress_max          = Utilities::MPI::max(stress_max, comm);
          }
        if (exact_displacement)
          {
            errors.l2_relative     = std::sqrt(l2 / l2_norm);
            errors.energy_relative = std::sqrt(energy / energy_norm);
            // Nodal error at the vertices, relative to the largest value;
            // the reference is evaluated a hair inside each cell, so that a
            // reference that jumps between bodies in contact is taken from
            // the vertex's own body.
            double         nodal = 0, largest = 0;
            Vector<double> exact(dim);
            for (const auto &cell : dof_handler.active_cell_iterators())
              for (const unsigned int v : cell->vertex_indices())
                if (cell->is_locally_owned())
                  {
                    const Point<dim> inside =
                      cell->vertex(v) +
                      1e-12 * (cell->center() - cell->vertex(v));
                    exact_displacement->vector_value(inside, exact);
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        nodal =
                          std::max(nodal,
                                   std::abs(
                                     solution(cell->vertex_dof_index(v, d)) -
                                     exact(d)));
                        largest = std::max(largest, std::abs(exact(d)));
                      }
                  }
            if (distributed)
              {
                nodal = Utilities::MPI::max(nodal, parallel::communicator());
                largest =
                  Utilities::MPI::max(largest, parallel::communicator());
              }
            // Absolute where the reference is zero everywhere.
            errors.nodal_relative = nodal / (largest > 0 ? largest : 1.);
          }
        if (exact_stress)
          errors.stress_relative = stress_error / stress_max;
      }
    if (exact_pressure && !pairs.empty())
      {
        double error = 0, largest = 0;
        for (unsigned int p = 0; p < pairs.size(); ++p)
          {
            const double exact =
              exact_pressure->value(pairs.points[p].position);
            error   = std::max(error, std::abs(results.pressure[p] - exact));
            largest = std::max(largest, std::abs(exact));
          }
        errors.pressure_relative = error / largest;
        double l2 = 0, norm = 0;
        for (unsigned int p = 0; p < pairs.size(); ++p)
          {
            const double exact =
              exact_pressure->value(pairs.points[p].position);
            const double weight = pairs.rows[p].length;
            l2 += weight * std::pow(results.pressure[p] - exact, 2);
            norm += weight * exact * exact;
          }
        errors.pressure_l2_relative = std::sqrt(l2 / norm);
      }
    double max_pressure = 0, length = 0;
    for (const auto &i : results.interfaces)
      {
        max_pressure = std::max(max_pressure, i.max_pressure);
        length += i.contact_length;
      }
    if (peak_pressure != 0)
      errors.peak_pressure_relative =
        std::abs(max_pressure - peak_pressure) / peak_pressure;
    if (contact_length != 0)
      errors.contact_length_error = std::abs(length - contact_length);
    if (reference_energy != 0)
      errors.energy_reference_relative =
        std::abs(results.energy - reference_energy) / reference_energy;
    if (!extreme_stress_material.empty())
      for (const auto &[id, range] : results.stress_yy_range)
        if (materials[id].name == extreme_stress_material)
          errors.stress_extreme_relative =
            std::abs((extreme_stress < 0 ? range.first : range.second) -
                     extreme_stress) /
            std::abs(extreme_stress);
    return errors;
  }



  double
  Errors::primary() const
  {
    return std::isnan(peak_pressure_relative) ? energy_relative
                                              : peak_pressure_relative;
  }



  template <int dim>
  unsigned int
  Verification<dim>::check_study(const std::vector<Errors> &uniform_errors,
                                 const std::vector<double> &uniform_dofs,
                                 const std::vector<Errors> &adaptive_errors,
                                 const std::vector<double> &adaptive_dofs,
                                 std::ostream              &out) const
  {
    unsigned int n_failed = 0;
    const auto   pass     = [&](const bool ok) {
      n_failed += ok ? 0 : 1;
      return ok ? "PASS" : "FAIL";
    };
    const unsigned int n = uniform_errors.size();
    // A solution the meshes represent exactly (a patch test): both
    // sequences' errors are round-off (1e-12 relative measured on the
    // contact patch; a real study's finest error is 1e-4 and more), which
    // neither decreases nor ranks the strategies.
    const double round_off = 1e-9;
    if (n > 0 && uniform_errors.back().primary() <= round_off)
      {
        out << "check adaptive against uniform refinement: void (the finest "
               "uniform error "
            << std::scientific << std::setprecision(3)
            << uniform_errors.back().primary() << std::defaultfloat
            << " is round-off, below " << round_off
            << ": the solution is exact on these meshes)" << std::endl;
        return 0;
      }
    if (n >= 3)
      {
        const bool decreasing =
          uniform_errors[n - 3].primary() > uniform_errors[n - 2].primary() &&
          uniform_errors[n - 2].primary() > uniform_errors[n - 1].primary();
        out << "check uniform error decreases over its last 3 cycles: "
            << pass(decreasing) << std::endl;
      }
    const double target = uniform_errors.back().primary();
    double       dofs   = std::numeric_limits<double>::infinity();
    for (unsigned int k = 0; k < adaptive_errors.size(); ++k)
      if (adaptive_errors[k].primary() <= target)
        dofs = std::min(dofs, adaptive_dofs[k]);
    const double ratio = dofs / uniform_dofs.back();
    out << "check adaptive dofs to reach the finest uniform error / uniform "
           "dofs: "
        << std::scientific << std::setprecision(3) << ratio << std::defaultfloat
        << " < 1: " << pass(ratio < 1) << std::endl;
    return n_failed;
  }



  template <int dim>
  unsigned int
  Verification<dim>::check(const Results<dim>        &results,
                           const ContactSolution     &contact,
                           const bool                 has_contact,
                           const std::vector<Errors> &errors,
                           const std::vector<double> &n_dofs,
                           std::ostream              &out) const
  {
    unsigned int n_failed = 0;
    const auto   report   = [&](const std::string &what,
                            const double       value,
                            const std::string &relation,
                            const double       bound) {
      const bool pass =
        relation == "<=" ? value <= bound : value >= bound; // NaN fails
      out << "check " << what << ": " << std::scientific << std::setprecision(3)
          << value << ' ' << relation << ' ' << bound << std::defaultfloat
          << ": " << (pass ? "PASS" : "FAIL") << std::endl;
      n_failed += pass ? 0 : 1;
    };

    const Errors &last = errors.back();
    if (exact_displacement && min_l2_rate == 0 && min_energy_rate == 0)
      report("relative nodal displacement error",
             last.nodal_relative,
             "<=",
             tolerance);
    if (exact_stress)
      report("relative stress error", last.stress_relative, "<=", tolerance);
    if (exact_pressure)
      report("relative contact pressure error",
             last.pressure_relative,
             "<=",
             tolerance);

    // Observed rates between successive cycles, h ~ n_dofs^(-1/dim).
    const auto min_rate = [&](double Errors::*error) {
      double rate = std::numeric_limits<double>::max();
      for (unsigned int k = 2; k < errors.size(); ++k)
        rate = std::min(rate,
                        std::log(errors[k - 1].*error / errors[k].*error) /
                          (std::log(n_dofs[k] / n_dofs[k - 1]) / dim));
      return rate;
    };
    if (min_l2_rate > 0)
      report("smallest L2 rate after the first refinement",
             min_rate(&Errors::l2_relative),
             ">=",
             min_l2_rate);
    if (min_energy_rate > 0)
      report("smallest energy rate after the first refinement",
             min_rate(&Errors::energy_relative),
             ">=",
             min_energy_rate);
    if (max_l2_error > 0)
      report("relative L2 error on the last mesh",
             last.l2_relative,
             "<=",
             max_l2_error);
    if (min_pressure_rate > 0)
      report("smallest contact pressure L2 rate after the first refinement",
             min_rate(&Errors::pressure_l2_relative),
             ">=",
             min_pressure_rate);

    if (has_contact && check_kkt)
      {
        double max_pressure = 0, min_pressure = 0;
        for (const double p : results.pressure)
          {
            max_pressure = std::max(max_pressure, p);
            min_pressure = std::min(min_pressure, p);
          }
        report("converged", contact.converged ? 1 : 0, ">=", 1);
        report("lambda >= 0: -min pressure / max pressure",
               max_pressure > 0 ? -min_pressure / max_pressure : 0,
               "<=",
               1e-10);
        report("A x <= g: max penetration / max |u|",
               results.max_displacement > 0
                 ? std::max(contact.max_penetration, 0.) /
                     results.max_displacement
                 : 0,
               "<=",
               1e-10);
        report("complementarity residual",
               contact.complementarity,
               "<=",
               std::max(1e-10, contact.tolerance));
        report(
          "equilibrium residual", results.equilibrium_residual, "<=", 1e-8);
      }
    if (peak_pressure != 0)
      report("relative error of the peak pressure",
             last.peak_pressure_relative,
             "<=",
             peak_tolerance);
    if (contact_length != 0)
      report("error of the contact length [m]",
             last.contact_length_error,
             "<=",
             length_tolerance);
    if (reference_energy != 0)
      report("relative error of the energy a(u,u)",
             last.energy_reference_relative,
             "<=",
             energy_tolerance);
    if (!extreme_stress_material.empty())
      report("relative error of the extreme tau_yy in '" +
               extreme_stress_material + "'",
             last.stress_extreme_relative,
             "<=",
             extreme_stress_tolerance);
    const auto check_forces =
      [&](const std::vector<std::pair<std::string, double>> &forces,
          const std::string                                 &parameter,
          const std::string                                 &what,
          const bool                                         tangential) {
        for (const auto &[name, force] : forces)
          {
            const auto it = std::find_if(results.interfaces.begin(),
                                         results.interfaces.end(),
                                         [&](const InterfaceResult<dim> &i) {
                                           return i.name == name;
                                         });
            AssertThrow(it != results.interfaces.end(),
                        ExcMessage("Verification/" + parameter +
                                   ": no contact interface named '" + name +
                                   "'"));
            const Tensor<1, dim> value =
              tangential ? it->tangential_force_on_slave
                         : Tensor<1, dim>(it->force_on_slave +
                                          it->tangential_force_on_slave);
            report("relative error of the " + what + " on '" + name + "'",
                   std::abs(value.norm() - force) / force,
                   "<=",
                   force_tolerance);
          }
      };
    check_forces(interface_forces,
                 "Reference contact forces",
                 "contact force",
                 false);
    check_forces(tangential_forces,
                 "Reference tangential forces",
                 "tangential force",
                 true);
    return n_failed;
  }


  template <int dim>
  void
  Verification<dim>::set_load_parameter(const double t)
  {
    for (auto *function :
         {exact_displacement.get(), exact_stress.get(), exact_pressure.get()})
      if (function != nullptr)
        function->set_time(t);
  }


  template class Verification<2>;
  template class Verification<3>;
} // namespace knee_contact
