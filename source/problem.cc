#include <knee_contact/elasticity.h>
#include <knee_contact/input.h>
#include <knee_contact/problem.h>
#include <knee_contact/rigid_modes.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_q.h>

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>

namespace knee_contact
{
  namespace
  {
    // Parse @p scene_file into @p prm and turn ParameterHandler's
    // multi-line messages into one line.
    void
    parse_scene(ParameterHandler  &prm,
                const std::string &scene_file,
                const bool         skip_undefined)
    {
      AssertThrow(std::ifstream(scene_file).good(),
                  ExcMessage("cannot open scene file '" + scene_file + "'"));
      const auto extension = std::filesystem::path(scene_file).extension();
      AssertThrow(extension == ".prm" || extension == ".json",
                  ExcMessage("scene file '" + scene_file +
                             "' must end in .prm or .json"));
      try
        {
          prm.parse_input(scene_file, "", skip_undefined);
        }
      catch (const ExceptionBase &exc)
        {
          std::ostringstream info;
          exc.print_info(info);
          AssertThrow(false,
                      ExcMessage(scene_file + ": " +
                                 input::one_line(info.str())));
        }
      catch (const std::exception &exc)
        {
          AssertThrow(false,
                      ExcMessage(scene_file + ": " +
                                 input::one_line(exc.what())));
        }
    }
  } // namespace



  ContactProblem::Counts
  ContactProblem::read_counts(const std::string &scene_file)
  {
    ParameterHandler prm;
    declare_parameters(prm, Counts{0, 0, 0});
    parse_scene(prm, scene_file, true);
    Counts counts;
    prm.enter_subsection("Materials");
    counts.n_materials = prm.get_integer("Number of materials");
    prm.leave_subsection();
    prm.enter_subsection("Boundary conditions");
    counts.n_conditions = prm.get_integer("Number of conditions");
    prm.leave_subsection();
    prm.enter_subsection("Contact");
    counts.n_interfaces = prm.get_integer("Number of interfaces");
    prm.leave_subsection();
    return counts;
  }



  void
  ContactProblem::declare_parameters(ParameterHandler &prm,
                                     const Counts     &counts)
  {
    MeshInput::declare_parameters(prm);
    Materials::declare_parameters(prm, counts.n_materials);
    BoundaryConditions::declare_parameters(prm, counts.n_conditions);
    ContactInterfaces::declare_parameters(prm, counts.n_interfaces);
    ActiveSetSolver::declare_parameters(prm);
    OutputWriter::declare_parameters(prm);
    Verification::declare_parameters(prm);
    prm.enter_subsection("Refinement");
    prm.declare_entry("Number of cycles",
                      "1",
                      Patterns::Integer(1, 12),
                      "Solve on this many meshes, refining every cell "
                      "between them; errors and rates are tabulated.");
    prm.leave_subsection();
  }



  ContactProblem::ContactProblem(const std::string &scene_file)
    : scene_file(scene_file)
    , fe(FE_Q<2>(1), 2)
  {
    const Counts     counts = read_counts(scene_file);
    ParameterHandler prm;
    declare_parameters(prm, counts);
    parse_scene(prm, scene_file, false);

    mesh_input.parse_parameters(prm, scene_file);
    materials.parse_parameters(prm, counts.n_materials);
    boundary_conditions.parse_parameters(prm, counts.n_conditions);
    contact_interfaces.parse_parameters(prm, counts.n_interfaces);
    active_set_solver.parse_parameters(prm, materials.max_youngs_modulus());
    output_writer.parse_parameters(prm, scene_file);
    verification.parse_parameters(prm);
    prm.enter_subsection("Refinement");
    n_cycles = prm.get_integer("Number of cycles");
    prm.leave_subsection();
  }



  std::ostream &
  ContactProblem::log() const
  {
    if (output_writer.test_mode())
      {
        quiet.str("");
        return quiet;
      }
    return std::cout;
  }



  void
  ContactProblem::make_mesh()
  {
    mesh_input.create(triangulation);
    materials.check_mesh(triangulation);
    boundary_conditions.check_mesh(triangulation);
    body_of_cell = compute_body_ids(triangulation, n_bodies);
    contact_interfaces.check_mesh(triangulation, body_of_cell);
  }



  void
  ContactProblem::check_scene()
  {
    make_mesh();
    std::cout << scene_file << ": " << triangulation.n_active_cells()
              << " cells, " << n_bodies << " bodies, "
              << contact_interfaces.interfaces().size()
              << " contact interfaces: OK" << std::endl;
  }



  void
  ContactProblem::setup_system()
  {
    dof_handler.reinit(triangulation);
    dof_handler.distribute_dofs(fe);
    body_of_cell = compute_body_ids(triangulation, n_bodies);
    body_names.assign(n_bodies, "");
    std::vector<std::set<types::material_id>> body_materials(n_bodies);
    for (const auto &cell : triangulation.active_cell_iterators())
      body_materials[body_of_cell[cell->active_cell_index()]].insert(
        cell->material_id());
    for (unsigned int b = 0; b < n_bodies; ++b)
      for (const auto id : body_materials[b])
        body_names[b] +=
          (body_names[b].empty() ? "" : ", ") + materials[id].name;

    boundary_conditions.make_constraints(dof_handler, constraints);
    contact_pairs = contact_interfaces.make_pairs(dof_handler, constraints);

    // One sparsity pattern serves every active set. Condensing a subset of
    // the contact lines couples each dof i with the dofs its line refers to,
    // E(i), so an entry (i, j) of the mesh's pattern needs E(i) x E(j) for
    // whichever of i, j are constrained; E(i) holds both the reduced row of
    // a pair (partner lines inactive) and its fully resolved form (partners
    // active), as well as the Gamma_u/Gamma_o entries.
    AffineConstraints<double> all_pairs;
    ActiveSetSolver::make_constraints(constraints,
                                      contact_pairs,
                                      std::vector<bool>(contact_pairs.size(),
                                                        true),
                                      all_pairs);
    std::map<types::global_dof_index, std::vector<types::global_dof_index>>
      expansion;
    for (const auto &line : all_pairs.get_lines())
      {
        auto &e = expansion[line.index];
        e.push_back(line.index);
        for (const auto &entry : line.entries)
          e.push_back(entry.first);
      }
    for (const auto &pair : contact_pairs)
      if (pair.eliminated != numbers::invalid_dof_index)
        for (const auto &entry : pair.reduced_row)
          expansion[pair.eliminated].push_back(entry.first);

    DynamicSparsityPattern mesh_pattern(dof_handler.n_dofs());
    DoFTools::make_sparsity_pattern(dof_handler, mesh_pattern);
    DynamicSparsityPattern dsp(dof_handler.n_dofs());
    for (types::global_dof_index i = 0; i < dof_handler.n_dofs(); ++i)
      {
        const auto ei = expansion.find(i);
        for (auto it = mesh_pattern.begin(i); it != mesh_pattern.end(i); ++it)
          {
            const types::global_dof_index j  = it->column();
            const auto                    ej = expansion.find(j);
            if (ei == expansion.end() && ej == expansion.end())
              dsp.add(i, j);
            else
              for (const auto a : ei == expansion.end()
                                    ? std::vector<types::global_dof_index>{i}
                                    : ei->second)
                for (const auto b : ej == expansion.end()
                                      ? std::vector<types::global_dof_index>{j}
                                      : ej->second)
                  dsp.add(a, b);
          }
      }
    sparsity_pattern.copy_from(dsp);
    system_matrix.reinit(sparsity_pattern);
  }



  int
  ContactProblem::run()
  {
    TimerOutput timer(log(), TimerOutput::never, TimerOutput::wall_times);
    output_writer.prepare();
    {
      TimerOutput::Scope scope(timer, "mesh");
      make_mesh();
    }

    std::vector<Errors> errors;
    std::vector<double> n_dofs;
    ConvergenceTable    table;
    Results             results;
    for (unsigned int cycle = 0; cycle < n_cycles; ++cycle)
      {
        if (cycle > 0)
          {
            TimerOutput::Scope scope(timer, "mesh");
            triangulation.refine_global(1);
          }
        {
          TimerOutput::Scope scope(timer, "setup");
          setup_system();
        }
        std::cout << "cycle " << cycle << ": " << triangulation.n_active_cells()
                  << " cells, " << dof_handler.n_dofs() << " dofs, " << n_bodies
                  << " bodies, " << contact_pairs.size() << " contact pairs"
                  << std::endl;
        {
          TimerOutput::Scope  scope(timer, "assembly");
          ElasticityAssembler assembler(materials, boundary_conditions);
          assembler.assemble(dof_handler, system_matrix, system_rhs);
        }
        {
          TimerOutput::Scope scope(timer, "solve");
          const RigidModes   rigid_modes(dof_handler, body_of_cell, body_names);
          try
            {
              contact_solution =
                active_set_solver.solve(system_matrix,
                                        system_rhs,
                                        constraints,
                                        contact_pairs,
                                        rigid_modes,
                                        displacement,
                                        contact_pairs.empty() ? quiet
                                                              : std::cout);
            }
          catch (const SparseDirectUMFPACK::ExcUMFPACKError &)
            {
              AssertThrow(false,
                          ExcMessage("UMFPACK: the stiffness matrix is "
                                     "singular; check that every body is "
                                     "held"));
            }
        }
        {
          TimerOutput::Scope scope(timer, "postprocess");
          results = compute_results(dof_handler,
                                    body_of_cell,
                                    system_matrix,
                                    system_rhs,
                                    displacement,
                                    materials,
                                    boundary_conditions,
                                    contact_interfaces,
                                    contact_pairs,
                                    contact_solution);
          errors.push_back(verification.compute_errors(
            dof_handler, displacement, materials, contact_pairs, results));
        }
        n_dofs.push_back(dof_handler.n_dofs());
        table.add_value("cycle", cycle);
        table.add_value("cells", triangulation.n_active_cells());
        table.add_value("dofs", dof_handler.n_dofs());
        if (!contact_pairs.empty())
          {
            table.add_value("pairs", contact_pairs.size());
            table.add_value("iterations", contact_solution.n_iterations);
            double peak = 0;
            for (const auto &i : results.interfaces)
              peak = std::max(peak, i.max_pressure);
            table.add_value("peak pressure", peak);
            table.set_scientific("peak pressure", true);
          }
        if (verification.has_exact_displacement())
          {
            table.add_value("L2 error", errors.back().l2_relative);
            table.add_value("energy error", errors.back().energy_relative);
            table.set_scientific("L2 error", true);
            table.set_scientific("energy error", true);
          }
      }

    if (verification.has_exact_displacement() && n_cycles > 1)
      {
        table.evaluate_convergence_rates("L2 error",
                                         "dofs",
                                         ConvergenceTable::reduction_rate_log2,
                                         2);
        table.evaluate_convergence_rates("energy error",
                                         "dofs",
                                         ConvergenceTable::reduction_rate_log2,
                                         2);
      }
    if (n_cycles > 1)
      table.write_text(std::cout);

    print_results(results);

    if (output_writer.enabled())
      {
        TimerOutput::Scope scope(timer, "output");
        output_writer.write_vtu(dof_handler,
                                body_of_cell,
                                displacement,
                                materials,
                                contact_pairs,
                                contact_solution,
                                results);
        output_writer.write_cells(dof_handler,
                                  body_of_cell,
                                  displacement,
                                  materials);
        output_writer.write_contact_csv(contact_interfaces,
                                        contact_pairs,
                                        displacement,
                                        contact_solution,
                                        results);
      }
    auto wall_times = timer.get_summary_data(TimerOutput::total_wall_time);
    if (output_writer.enabled())
      output_writer.write_summary(results,
                                  contact_solution,
                                  materials,
                                  wall_times);
    if (output_writer.enabled())
      {
        TimerOutput::Scope scope(timer, "pictures");
        std::string        message;
        if (!output_writer.make_pictures(message))
          std::cout << "warning: no pictures: " << message << std::endl;
      }
    if (!output_writer.test_mode())
      {
        std::cout << "wall time [s]:";
        for (const auto &[phase, seconds] : wall_times)
          std::cout << "  " << phase << " " << std::setprecision(3) << seconds;
        std::cout << std::endl;
        if (output_writer.enabled())
          std::cout << "results in " << output_writer.folder() << "/"
                    << std::endl;
      }

    const unsigned int n_failed = verification.check(results,
                                                     contact_solution,
                                                     !contact_pairs.empty(),
                                                     errors,
                                                     n_dofs,
                                                     std::cout);
    if (!contact_solution.converged)
      {
        std::cerr << "knee_contact: not converged: " << contact_solution.failure
                  << " (last iterate written with converged = false)"
                  << std::endl;
        return ExitCode::not_converged;
      }
    if (n_failed > 0)
      {
        std::cerr << "knee_contact: " << n_failed
                  << " verification check(s) failed" << std::endl;
        return ExitCode::verification_failed;
      }
    return ExitCode::success;
  }



  void
  ContactProblem::print_results(const Results &results) const
  {
    std::ostream &out = std::cout;
    out << std::scientific << std::setprecision(6);
    out << "results:\n"
        << "  dofs " << results.n_dofs << ", cells " << results.n_cells
        << ", bodies " << results.n_bodies << "\n"
        << "  applied load [N/m]           (" << results.applied_load[0] << ", "
        << results.applied_load[1] << ")\n";
    for (const auto &[id, reaction] : results.reactions)
      out << "  reaction at boundary id " << std::setw(3) << id << " [N/m] ("
          << reaction[0] << ", " << reaction[1] << ")\n";
    out << "  equilibrium residual         " << std::setprecision(2)
        << results.equilibrium_residual << std::setprecision(6) << "\n"
        << "  energy a(u,u) [J/m]          " << results.energy << "\n"
        << "  max |u| [m]                  " << results.max_displacement
        << "\n";
    for (const auto &[id, range] : results.stress_yy_range)
      out << "  tau_yy [Pa] in " << std::left << std::setw(14)
          << materials[id].name << std::right << " [" << range.first << ", "
          << range.second << "]\n";
    for (const auto &i : results.interfaces)
      out << "  contact '" << i.name << "': " << i.n_active << " of "
          << i.n_pairs << " pairs active, force [N/m] " << i.force
          << ", peak pressure [Pa] " << i.max_pressure
          << ", contact length [m] " << i.contact_length << "\n";
    if (!contact_pairs.empty())
      out << "  active-set iterations " << contact_solution.n_iterations
          << (contact_solution.converged ? ", converged" : ", NOT converged")
          << "\n";
    if (output_writer.test_mode())
      for (unsigned int p = 0; p < contact_pairs.size(); ++p)
        if (contact_solution.active[p])
          out << "  pair at (" << contact_pairs[p].position[0] << ", "
              << contact_pairs[p].position[1] << ") pressure [Pa] "
              << results.pressure[p] << "\n";
    out << std::defaultfloat << std::flush;
  }
} // namespace knee_contact
