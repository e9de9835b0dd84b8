#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/core/input.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/mesh/scene_checks.h>
#include <knee_contact/core/scene_file.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>

#include <deal.II/dofs/dof_tools.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iomanip>
#include <iostream>
#include <map>
#include <new>
#include <set>

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



  template <int dim>
  typename ContactProblem<dim>::Counts
  ContactProblem<dim>::read_counts(const std::string &scene_file)
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



  template <int dim>
  void
  ContactProblem<dim>::declare_parameters(ParameterHandler &prm,
                                     const Counts     &counts)
  {
    MeshInput<dim>::declare_parameters(prm);
    Materials<dim>::declare_parameters(prm, counts.n_materials);
    BoundaryConditions<dim>::declare_parameters(prm, counts.n_conditions);
    ContactInterfaces::declare_parameters(prm, counts.n_interfaces);
    ActiveSetSolver::declare_parameters(prm);
    LoadCases::declare_parameters(prm);
    OutputWriter<dim>::declare_parameters(prm);
    Verification<dim>::declare_parameters(prm);
    Refinement::declare_parameters(prm);
  }



  template <int dim>
  ContactProblem<dim>::ContactProblem(const std::string &scene_file)
    : scene_file(scene_file)
  {
    const Counts       counts = read_counts(scene_file);
    const SceneOutline outline(scene_file);
    outline.check_numbered("Materials",
                           "Material",
                           counts.n_materials,
                           "Number of materials");
    outline.check_numbered("Boundary conditions",
                           "Condition",
                           counts.n_conditions,
                           "Number of conditions");
    outline.check_numbered("Contact",
                           "Interface",
                           counts.n_interfaces,
                           "Number of interfaces");
    ParameterHandler prm;
    declare_parameters(prm, counts);
    parse_scene(prm, scene_file, false);

    mesh_input.parse_parameters(prm, scene_file);
    materials.parse_parameters(prm, counts.n_materials);
    boundary_conditions.parse_parameters(prm, counts.n_conditions);
    contact_interfaces.parse_parameters(prm, counts.n_interfaces);
    active_set_solver.parse_parameters(prm, materials.max_youngs_modulus());
    load_cases.parse_parameters(prm);
    output_writer.parse_parameters(prm, scene_file);
    verification.parse_parameters(prm);
    refinement.parse_parameters(prm);
    mesh_input.adaptive = refinement.strategy != Refinement::Strategy::global;
    scene_checks::check_roles(boundary_conditions, contact_interfaces);
    AssertThrow(dim == 2 || contact_interfaces.interfaces().empty(),
                ExcMessage("Contact/Number of interfaces: the mesh is 3D and "
                           "3D contact is not implemented yet (3D elasticity "
                           "is); set it to 0 and hold every body by boundary "
                           "conditions"));
  }



  template <int dim>
  std::ostream &
  ContactProblem<dim>::log() const
  {
    if (output_writer.test_mode())
      {
        quiet.str("");
        return quiet;
      }
    return std::cout;
  }



  template <int dim>
  void
  ContactProblem<dim>::make_mesh(const unsigned int level)
  {
    mesh_input.create(triangulation, level);
    fe =
      elements::displacement_element<dim>(elements::cell_kind(triangulation));
    materials.check_mesh(triangulation);
    boundary_conditions.check_mesh(triangulation);
    body_of_cell = compute_body_ids(triangulation, n_bodies);
    scene_checks::check_joints(triangulation, body_of_cell);
    contact_interfaces.check_mesh(triangulation, body_of_cell);
  }



  template <int dim>
  void
  ContactProblem<dim>::check_scene()
  {
    make_mesh(0);
    std::cout << scene_file << ": " << triangulation.n_active_cells()
              << " cells, " << n_bodies << " bodies, "
              << contact_interfaces.interfaces().size()
              << " contact interfaces: OK" << std::endl;
  }



  template <int dim>
  void
  ContactProblem<dim>::setup_system()
  {
    dof_handler.reinit(triangulation);
    dof_handler.distribute_dofs(*fe);
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

    DynamicSparsityPattern mesh_pattern(dof_handler.n_dofs());
    DoFTools::make_sparsity_pattern(dof_handler, mesh_pattern);
    ActiveSetSolver::make_sparsity_pattern(mesh_pattern,
                                           constraints,
                                           contact_pairs.rows,
                                           sparsity_pattern);
    system_matrix.reinit(sparsity_pattern);
  }



  template <int dim>
  std::vector<CycleRecord>
  ContactProblem<dim>::run_cycles(const Refinement::Strategy strategy,
                             TimerOutput               &timer,
                             Results<dim>              &results)
  {
    std::vector<CycleRecord> records;
    const unsigned int       n_cycles = strategy == Refinement::Strategy::global
                                          ? refinement.n_cycles
                                          : refinement.n_adaptive_cycles;
    for (unsigned int cycle = 0; cycle < n_cycles; ++cycle)
      {
        CycleRecord record;
        record.strategy = Refinement::name(strategy);
        record.cycle    = cycle;
        // Each phase goes to the run's TimerOutput and to this cycle's row.
        const auto timed = [&](const std::string           &phase,
                               const std::function<void()> &work) {
          TimerOutput::Scope scope(timer, phase);
          Timer              clock;
          work();
          record.wall_time[phase] += clock.wall_time();
        };

        timed("mesh", [&]() {
          if (cycle == 0)
            make_mesh(0);
          else if (strategy == Refinement::Strategy::global &&
                   mesh_input.remeshes(triangulation))
            make_mesh(cycle);
          else
            {
              refinement.refine(strategy,
                                triangulation,
                                dof_handler,
                                displacement,
                                materials,
                                contact_interfaces,
                                contact_pairs,
                                contact_solution);
              check_cells(triangulation);
            }
          scene_checks::check_finite_data(triangulation,
                                          materials,
                                          boundary_conditions);
        });
        timed("setup", [&]() { setup_system(); });
        std::cout << record.strategy << " cycle " << cycle << ": "
                  << triangulation.n_active_cells() << " cells, "
                  << dof_handler.n_dofs() << " dofs, " << n_bodies
                  << " bodies, " << contact_pairs.size() << " contact pairs"
                  << std::endl;
        timed("assembly", [&]() {
          ElasticityAssembler<dim> assembler(materials, boundary_conditions);
          assembler.assemble(dof_handler, system_matrix, system_rhs);
        });
        timed("solve", [&]() {
          // Warm start on a refined mesh: pairs within the previous contact
          // zone start active (the loop corrects the guess).
          std::vector<bool> guess;
          if (cycle > 0)
            {
              guess.assign(contact_pairs.size(), false);
              for (unsigned int p = 0; p < contact_pairs.size(); ++p)
                for (const auto &[position, length] : previous_contact)
                  if (contact_pairs.points[p].position.distance(position) <=
                      length)
                    guess[p] = true;
            }
          solve_contact(guess, true);
        });
        timed("postprocess", [&]() {
          results       = current_results();
          record.errors = verification.compute_errors(
            dof_handler, displacement, materials, contact_pairs, results);
        });

        previous_contact.clear();
        for (unsigned int p = 0; p < contact_pairs.size(); ++p)
          if (contact_solution.active[p])
            previous_contact.emplace_back(
              contact_pairs.points[p].position,
              std::pow(contact_pairs.rows[p].length, 1. / (dim - 1)));
        record.n_cells        = triangulation.n_active_cells();
        record.n_dofs         = dof_handler.n_dofs();
        record.n_pairs        = contact_pairs.size();
        record.n_iterations   = contact_solution.n_iterations;
        record.solver         = solver_name;
        record.solver_figures = solver_figures;
        record.energy         = results.energy;
        for (const auto &i : results.interfaces)
          record.peak_pressure = std::max(record.peak_pressure, i.max_pressure);
        for (const auto &phase : record.wall_time)
          record.total_time += phase.second;
        if (!output_writer.test_mode())
          std::cout << std::setprecision(7) << "   " << record.n_dofs
                    << " dofs: peak pressure " << record.peak_pressure
                    << ", energy " << record.energy << ", " << record.total_time
                    << " s" << std::endl;
        Utilities::System::MemoryStats memory;
        Utilities::System::get_memory_stats(memory);
        record.peak_memory = memory.VmHWM / 1024.;
        records.push_back(record);
        if (!contact_solution.converged)
          break;
      }
    return records;
  }



  template <int dim>
  void
  ContactProblem<dim>::solve_contact(const std::vector<bool> &guess,
                                const bool               new_matrix)
  {
    const RigidModes<dim> rigid_modes(dof_handler, body_of_cell, body_names);
    std::ostream    &loop_log = contact_pairs.empty() ? quiet : std::cout;
    try
      {
        Timer clock;
        if (new_matrix)
          {
            solver_figures.clear();
            contact_system.reset();
            contact_system =
              make_contact_system(active_set_solver.linear_solver(),
                                  system_matrix,
                                  constraints,
                                  contact_pairs.rows,
                                  !guess.empty(),
                                  output_writer.test_mode() ? quiet : loop_log,
                                  solver_name,
                                  solver_figures);
          }
        contact_system->set_rhs(system_rhs);
        contact_solution = active_set_solver.solve(*contact_system,
                                                   system_rhs.linfty_norm(),
                                                   constraints,
                                                   contact_pairs.rows,
                                                   rigid_modes,
                                                   guess,
                                                   loop_log);
        contact_system->solution(displacement);
        solver_figures["contact_solve"] = clock.wall_time();
        for (const auto &[name, value] : contact_system->statistics())
          solver_figures[name] = value;
        if (new_matrix && active_set_solver.measure_reference())
          {
            Vector<double> x;
            solver_figures["reference_solve"] =
              reference_solve(system_matrix,
                              system_rhs,
                              constraints,
                              contact_pairs.rows,
                              contact_solution.active,
                              x);
            x -= displacement;
            solver_figures["reference_difference"] =
              x.linfty_norm() / std::max(displacement.linfty_norm(), 1e-300);
          }
      }
    catch (const ContactSystem::ExcNotPositiveDefinite &)
      {
        AssertThrow(false,
                    ExcMessage("the stiffness matrix is singular "
                               "under the active contact rows; check "
                               "that every body is held"));
      }
    catch (const SparseDirectUMFPACK::ExcUMFPACKError &exc)
      {
        // UMFPACK's status: 1 singular, -1 out of memory.
        std::ostringstream info;
        exc.print_info(info);
        const bool memory = info.str().find("status -1") != std::string::npos;
        if (memory)
          throw std::bad_alloc();
        AssertThrow(false,
                    ExcMessage("UMFPACK: the stiffness matrix is "
                               "singular; check that every body is "
                               "held"));
      }
    // Finite data and moduli were checked; a non-finite solution
    // means they are too extreme together for double precision.
    for (const double u : displacement)
      AssertThrow(std::isfinite(u),
                  ExcMessage("the solution is not finite: the loads and "
                             "displacements are too large for the moduli "
                             "(E from " +
                             std::to_string(materials.min_youngs_modulus()) +
                             " to " +
                             std::to_string(materials.max_youngs_modulus()) +
                             " Pa); choose units that keep them near 1"));
  }



  template <int dim>
  Results<dim>
  ContactProblem<dim>::current_results() const
  {
    return compute_results(dof_handler,
                           body_of_cell,
                           system_matrix,
                           system_rhs,
                           displacement,
                           materials,
                           boundary_conditions,
                           contact_interfaces,
                           contact_pairs,
                           contact_solution);
  }



  template <int dim>
  void
  ContactProblem<dim>::set_load_parameter(const double t)
  {
    materials.set_load_parameter(t);
    boundary_conditions.set_load_parameter(t);
    verification.set_load_parameter(t);
  }



  template <int dim>
  void
  ContactProblem<dim>::write_result_set(
    const Results<dim>                          &results,
    const std::vector<std::vector<CycleRecord>> &sequences,
    TimerOutput                                 &timer)
  {
    // Declared first: if anything below throws, its destructor waits for
    // the VTU thread before the objects it reads go.
    std::future<void> vtu;
    {
      TimerOutput::Scope scope(timer, "output");
      // The VTU (DataOut's patches and zlib: 95 % of the output time,
      // measured 2.2 s of 2.3 s at 4.3e5 Hertz dofs) is written on a second
      // thread while the other files, the summary and the pictures are
      // made, and joined before the folder is committed; everything it
      // reads is read-only by then.
      vtu = std::async(std::launch::async, [&]() {
        TimerOutput::Scope part(timer, "output: vtu");
        output_writer.write_vtu(dof_handler,
                                body_of_cell,
                                displacement,
                                materials,
                                contact_pairs,
                                contact_solution,
                                results);
      });
      {
        TimerOutput::Scope part(timer, "output: cells.npy");
        output_writer.write_cells(dof_handler,
                                  body_of_cell,
                                  displacement,
                                  results);
      }
      TimerOutput::Scope part(timer, "output: csv");
      output_writer.write_contact_csv(contact_interfaces,
                                      contact_pairs,
                                      displacement,
                                      contact_solution,
                                      results);
      std::size_t n_records = 0;
      for (const auto &records : sequences)
        n_records += records.size();
      if (n_records > 1)
        output_writer.write_file("study.csv", [&](std::ostream &out) {
          std::vector<CycleRecord> all;
          for (const auto &records : sequences)
            all.insert(all.end(), records.begin(), records.end());
          write_study_csv(all, out);
        });
    }
    Utilities::System::MemoryStats memory;
    Utilities::System::get_memory_stats(memory);
    solver_figures["peak_memory_MB"] = memory.VmHWM / 1024.;
    // Where the memory goes (deal.II's own accounting of its objects; the
    // solver's factor is factor_memory_MB).
    solver_figures["memory_mesh_MB"] =
      triangulation.memory_consumption() / 1048576.;
    solver_figures["memory_dofs_MB"] =
      dof_handler.memory_consumption() / 1048576.;
    solver_figures["memory_matrix_MB"] =
      (sparsity_pattern.memory_consumption() +
       system_matrix.memory_consumption()) /
      1048576.;
    // The pictures read summary.json; a picture failure is kept in it
    // as a warning.
    const auto summary = [&]() {
      output_writer.write_summary(results,
                                  contact_solution,
                                  materials,
                                  timer.get_summary_data(
                                    TimerOutput::total_wall_time),
                                  solver_name,
                                  solver_figures);
    };
    summary();
    {
      TimerOutput::Scope scope(timer, "pictures");
      std::string        message;
      if (!output_writer.run_script(dim == 2 ? "plot_results.py"
                                             : "plot_results_3d.py",
                                    message) ||
          (sequences.size() > 1 &&
           !output_writer.run_script("plot_study.py", message)))
        output_writer.warn("no pictures: " + message);
    }
    {
      TimerOutput::Scope scope(timer, "output");
      vtu.get();
    }
    // Again, with the VTU's time and any warning of the pictures.
    summary();
  }



  template <int dim>
  unsigned int
  ContactProblem<dim>::run_load_cases(
    const Results<dim>                          &first_results,
    const std::vector<std::vector<CycleRecord>> &sequences,
    TimerOutput                                 &timer)
  {
    const std::vector<double>          &t = load_cases.values();
    std::vector<LoadCases::Record<dim>> records;
    const auto                     record = [&](const double   t_case,
                            const double   solve_time,
                            const Results<dim> &results) {
      LoadCases::Record<dim> r;
      r.t            = t_case;
      r.n_iterations = contact_solution.n_iterations;
      r.converged    = contact_solution.converged;
      r.solve_time   = solve_time;
      r.results      = results;
      // The table needs the figures, not the per-cell and per-pair fields
      // (tens of MB per case on a fine mesh).
      decltype(r.results.vertex_stress_yy)().swap(r.results.vertex_stress_yy);
      decltype(r.results.vertex_von_mises)().swap(r.results.vertex_von_mises);
      std::vector<double>().swap(r.results.pressure);
      records.push_back(std::move(r));
    };
    record(t[0], solver_figures["contact_solve"], first_results);
    if (output_writer.enabled())
      {
        output_writer.set_subfolder(LoadCases::folder(0));
        write_result_set(first_results, sequences, timer);
      }

    unsigned int n_failed = 0;
    for (unsigned int c = 1; c < t.size() && contact_solution.converged; ++c)
      {
        std::cout << "load case " << c << ": t = " << t[c] << std::endl;
        set_load_parameter(t[c]);
        Timer clock;
        {
          TimerOutput::Scope scope(timer, "load cases: assembly");
          ElasticityAssembler<dim>(materials, boundary_conditions)
            .assemble_rhs(dof_handler, system_rhs);
        }
        {
          TimerOutput::Scope scope(timer, "load cases: solve");
          // The previous case's active set is the guess: loads along a
          // cycle change little from case to case.
          solve_contact(contact_solution.active, false);
        }
        const double solve_time = clock.wall_time();
        Results<dim> results;
        {
          TimerOutput::Scope scope(timer, "postprocess");
          results = current_results();
        }
        print_results(results);
        const Errors errors = verification.compute_errors(
          dof_handler, displacement, materials, contact_pairs, results);
        n_failed += verification.check(results,
                                       contact_solution,
                                       !contact_pairs.empty(),
                                       {errors},
                                       {double(dof_handler.n_dofs())},
                                       std::cout);
        record(t[c], solve_time, results);
        if (output_writer.enabled())
          {
            output_writer.set_subfolder(LoadCases::folder(c));
            write_result_set(results, {}, timer);
          }
      }

    LoadCases::print_table(records, !output_writer.test_mode(), std::cout);
    if (output_writer.enabled())
      {
        output_writer.set_subfolder("");
        output_writer.write_file("load_cases.csv", [&](std::ostream &out) {
          LoadCases::write_csv(records, out);
        });
        // A ParaView series: open load_cases.pvd and step through t.
        output_writer.write_file("load_cases.pvd", [&](std::ostream &out) {
          std::vector<std::pair<double, std::string>> series;
          for (unsigned int c = 0; c < records.size(); ++c)
            series.emplace_back(records[c].t,
                                LoadCases::folder(c) + "/solution.vtu");
          DataOutBase::write_pvd_record(out, series);
        });
        TimerOutput::Scope scope(timer, "pictures");
        std::string        message;
        if (!output_writer.run_script("plot_load_cases.py", message))
          std::cout << "knee_contact: warning: no load-case plot: " << message
                    << std::endl;
      }
    return n_failed;
  }



  template <int dim>
  int
  ContactProblem<dim>::run()
  {
    TimerOutput timer(log(), TimerOutput::never, TimerOutput::wall_times);
    output_writer.prepare();
    set_load_parameter(load_cases.values()[0]);

    // A study runs the uniform sequence first; the files and checks are
    // those of the last sequence.
    std::vector<Refinement::Strategy> strategies = {refinement.strategy};
    if (refinement.strategy == Refinement::Strategy::compare)
      strategies = {Refinement::Strategy::global,
                    Refinement::Strategy::adaptive};
    std::vector<std::vector<CycleRecord>> sequences;
    Results<dim>                          results;
    for (const auto strategy : strategies)
      sequences.push_back(run_cycles(strategy, timer, results));
    for (const auto &records : sequences)
      if (records.size() > 1)
        print_convergence_table(records,
                                dim,
                                !output_writer.test_mode(),
                                std::cout);

    print_results(results);

    std::vector<std::vector<Errors>> errors(sequences.size());
    std::vector<std::vector<double>> n_dofs(sequences.size());
    for (unsigned int s = 0; s < sequences.size(); ++s)
      for (const auto &record : sequences[s])
        {
          errors[s].push_back(record.errors);
          n_dofs[s].push_back(record.n_dofs);
        }
    unsigned int n_failed = verification.check(results,
                                               contact_solution,
                                               !contact_pairs.empty(),
                                               errors.back(),
                                               n_dofs.back(),
                                               std::cout);
    if (sequences.size() > 1)
      n_failed += verification.check_study(
        errors[0], n_dofs[0], errors[1], n_dofs[1], std::cout);

    if (load_cases.values().size() > 1)
      n_failed += run_load_cases(results, sequences, timer);
    else if (output_writer.enabled())
      write_result_set(results, sequences, timer);

    const auto wall_times =
      timer.get_summary_data(TimerOutput::total_wall_time);
    output_writer.commit();
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

    if (!contact_solution.converged)
      {
        std::cerr << "knee_contact: not converged: " << contact_solution.failure
                  << (output_writer.enabled()
                        ? " (last iterate written with converged = false)"
                        : "")
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



  template <int dim>
  void
  ContactProblem<dim>::print_results(const Results<dim> &results) const
  {
    std::ostream &out = std::cout;
    // Per unit thickness in 2D.
    const std::string force_unit  = dim == 2 ? "[N/m]" : "[N]  ";
    const std::string energy_unit = dim == 2 ? "[J/m]" : "[J]  ";
    const auto        list = [](const auto &v, const auto &shown) {
      std::ostringstream text;
      text << std::scientific << std::setprecision(6);
      for (unsigned int d = 0; d < dim; ++d)
        text << (d == 0 ? "(" : ", ") << shown(v[d]);
      return text.str() + ")";
    };
    out << std::scientific << std::setprecision(6);
    out << "results:\n"
        << "  dofs " << results.n_dofs << ", cells " << results.n_cells
        << ", bodies " << results.n_bodies << "\n"
        << "  applied load " << force_unit << "           "
        << list(results.applied_load, [](const double f) { return f; })
        << "\n";
    // A reaction component that is zero by physics comes out as round-off
    // of the force scale (1e-8 N/m beside 1e6 N/m); printed as it is, it
    // would make every comparison of this table with an earlier run fail on
    // noise. Components below 1e-10 of the force scale (the largest
    // force, or E max |u| where no force is applied: a rigid motion) are
    // shown as 0; so are an energy below 1e-10 E max|u|^2 and a stress
    // below 1e-12 E.
    const double E = materials.max_youngs_modulus();
    double       force_scale =
      std::max(results.applied_load.norm(), E * results.max_displacement);
    for (const auto &[id, reaction] : results.reactions)
      force_scale = std::max(force_scale, reaction.norm());
    const auto shown = [force_scale](const double f) {
      return std::abs(f) <= 1e-10 * force_scale ? 0. : f;
    };
    const double energy_noise =
      1e-10 * E * results.max_displacement * results.max_displacement;
    const auto shown_stress = [E](const double s) {
      return std::abs(s) <= 1e-12 * E ? 0. : s;
    };
    for (const auto &[id, reaction] : results.reactions)
      out << "  reaction at boundary id " << std::setw(3) << id << " "
          << force_unit << " " << list(reaction, shown) << "\n";
    out << "  equilibrium residual         " << std::setprecision(2)
        << results.equilibrium_residual << std::setprecision(6) << "\n"
        << "  energy a(u,u) " << energy_unit << "          "
        << (std::abs(results.energy) <= energy_noise ? 0. : results.energy)
        << "\n"
        << "  max |u| [m]                  " << results.max_displacement
        << "\n";
    for (const auto &[id, range] : results.stress_yy_range)
      out << "  tau_yy [Pa] in " << std::left << std::setw(14)
          << materials[id].name << std::right << " ["
          << shown_stress(range.first) << ", " << shown_stress(range.second)
          << "]\n";
    if (dim == 3)
      for (const auto &[id, value] : results.von_mises_max)
        out << "  max von Mises [Pa] in " << std::left << std::setw(14)
            << materials[id].name << std::right << " " << shown_stress(value)
            << "\n";
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
          out << "  pair at "
              << list(contact_pairs.points[p].position,
                      [](const double x) { return x; })
              << " pressure [Pa] " << results.pressure[p] << "\n";
    out << std::defaultfloat << std::flush;
  }



  unsigned int
  scene_dimension(const std::string &scene_file)
  {
    ParameterHandler prm;
    MeshInput<2>::declare_parameters(prm);
    parse_scene(prm, scene_file, true);
    return scene_dimension(prm, scene_file);
  }



  template class ContactProblem<2>;
  template class ContactProblem<3>;
} // namespace knee_contact
