// The files of a run: result sets, load cases and the results table
// (ContactProblem's output, split from problem.cc by job).
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/base/progress.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/physics/elasticity.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <cmath>
#include <future>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace knee_contact
{
  template <int dim>
  void
  ContactProblem<dim>::write_result_set(
    const Results<dim>                          &results,
    const std::vector<std::vector<CycleRecord>> &sequences,
    TimerOutput                                 &timer)
  {
    // The largest peak of the ranks before the output (issue 38's memory
    // per rank; rank 0's own, with the output's, is peak_memory_MB): every
    // rank that takes part in the output comes here, as all do or none.
    const double largest_rank_peak_MB =
      Utilities::MPI::max(memory::peak_resident_MB(), parallel::communicator());
    const auto write_vtu = [&]() {
      TimerOutput::Scope part(timer, "output: vtu");
      output_writer.write_vtu(dof_handler,
                              body_of_cell,
                              displacement,
                              materials,
                              contact_pairs,
                              contact_solution,
                              results);
    };
    // On a distributed mesh the cells' file is gathered from every rank
    // (one collective call), before the VTU's pieces are sent on another
    // thread: MPI is not called from two threads at once.
    const auto write_cells = [&]() {
      TimerOutput::Scope part(timer,
                              dim == 2 ? "output: cells.npy"
                                       : "output: surface.npy");
      output_writer.write_cells(dof_handler,
                                body_of_cell,
                                displacement,
                                results);
    };
    if (!output_writer.enabled())
      {
        // Another rank than 0 under mpirun: its pieces of solution.vtu,
        // and on a distributed mesh its rows of the cells' file.
        if (distributed)
          write_cells();
        write_vtu();
        return;
      }
    if (distributed)
      write_cells();
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
      vtu = std::async(std::launch::async, write_vtu);
      if (!distributed)
        write_cells();
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
    solver_figures["peak_memory_MB"] = memory::peak_resident_MB();
    if (mesh_peak_MB > 0)
      solver_figures["mesh_peak_memory_MB"] = mesh_peak_MB;
    if (estimated_first_MB > 0)
      {
        solver_figures["estimated_first_rank_MB"] = estimated_first_MB;
        solver_figures["estimated_rank_MB"]       = estimated_other_MB;
      }
    if (parallel::n_ranks() > 1)
      solver_figures["largest_rank_peak_memory_MB"] = largest_rank_peak_MB;
    // Where the memory goes (deal.II's own accounting of its objects; the
    // solver's factor is factor_memory_MB).
    solver_figures["memory_mesh_MB"] = mesh().memory_consumption() / 1048576.;
    solver_figures["memory_dofs_MB"] =
      dof_handler.memory_consumption() / 1048576.;
    // On a distributed mesh C's rows are the path's (iterative_memory_MB).
    if (!distributed)
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
                                  phase_times(timer),
                                  solver_name,
                                  solver_figures,
                                  error_estimates);
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
    // Again, with the VTU's time, any warning of the pictures and the
    // peak memory including the VTU's (its thread may still have been
    // building patches when the first summary was written).
    solver_figures["peak_memory_MB"] = memory::peak_resident_MB();
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
    const auto                          record = [&](const double        t_case,
                            const double        solve_time,
                            const Results<dim> &results) {
      LoadCases::Record<dim> r;
      r.t            = t_case;
      r.n_iterations = contact_solution.n_iterations;
      r.converged    = contact_solution.converged;
      r.solve_time   = solve_time;
      r.results      = results;
      const auto energy = error_estimates.find("energy");
      if (energy != error_estimates.end())
        r.energy_error = energy->second.error;
      const auto peak = error_estimates.find("peak pressure");
      if (peak != error_estimates.end())
        r.peak_pressure_error = peak->second.error;
      // The table needs the figures, not the per-cell and per-pair fields
      // (tens of MB per case on a fine mesh).
      decltype(r.results.vertex_stress_yy)().swap(r.results.vertex_stress_yy);
      decltype(r.results.vertex_von_mises)().swap(r.results.vertex_von_mises);
      std::vector<double>().swap(r.results.pressure);
      records.push_back(std::move(r));
    };
    record(t[0], solver_figures["contact_solve"], first_results);
    if (output_writer.takes_part())
      {
        output_writer.set_subfolder(LoadCases::folder(0));
        write_result_set(first_results, sequences, timer);
      }

    // The first case's error bars come from its mesh sequence; a further
    // case is solved on the last mesh only: it has the bars made on one
    // mesh (the energy's strain recovery, the peak pressures' goal-oriented
    // estimate), no sequence bars.
    unsigned int n_failed = 0;
    Progress     progress(log(), "load case", t.size() - 1, false, 1);
    for (unsigned int c = 1; c < t.size() && contact_solution.converged; ++c)
      {
        std::cout << "load case " << c << ": t = " << t[c] << std::endl;
        set_load_parameter(t[c]);
        Timer             clock;
        Timer             case_clock;
        std::vector<bool> guess = contact_solution.active;
        {
          TimerOutput::Scope scope(timer, "load cases: assembly");
          if (motions.empty())
            ElasticityAssembler<dim>(materials, boundary_conditions)
              .assemble_rhs(dof_handler, system_rhs);
          else
            guess = move_to_case(t[c - 1], t[c]);
        }
        {
          TimerOutput::Scope scope(timer, "load cases: solve");
          // The previous case's active set is the guess: loads along a
          // cycle change little from case to case. Moved bodies: a new
          // mesh position, a new system.
          solve_contact(guess, !motions.empty(), !motions.empty());
        }
        const double solve_time = clock.wall_time();
        Results<dim> results;
        {
          TimerOutput::Scope scope(timer, "postprocess");
          results = current_results();
        }
        error_estimates.clear();
        {
          TimerOutput::Scope scope(timer, "error estimate");
          const double eta_squared = estimate_mesh_errors(results, false, {});
          error_estimates["energy"] =
            recovered_energy_estimate(results.energy, eta_squared);
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
        if (output_writer.takes_part())
          {
            output_writer.set_subfolder(LoadCases::folder(c));
            write_result_set(results, {}, timer);
          }
        // Case c is the (c - 1)-th after the first, which the cycles solved.
        progress.step_done(c - 1, case_clock.wall_time());
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
  void
  ContactProblem<dim>::print_results(const Results<dim> &results) const
  {
    std::ostream &out = std::cout;
    // Per unit thickness in 2D.
    const std::string force_unit  = dim == 2 ? "[N/m]" : "[N]  ";
    const std::string energy_unit = dim == 2 ? "[J/m]" : "[J]  ";
    const auto        list        = [](const auto &v, const auto &shown) {
      std::ostringstream text;
      text << std::scientific << std::setprecision(6);
      for (unsigned int d = 0; d < dim; ++d)
        text << (d == 0 ? "(" : ", ") << shown(v[d]);
      return text.str() + ")";
    };
    // The error bar of a quantity (estimate_errors()), not in test mode:
    // the test terminal is a regression record of the solution, and the
    // bars are asserted by their own tests.
    const auto bar = [this](const std::string &name) {
      const auto found = error_estimates.find(name);
      if (output_writer.test_mode() || found == error_estimates.end() ||
          !std::isfinite(found->second.error))
        return std::string();
      std::ostringstream text;
      text << std::scientific << std::setprecision(1) << " +- "
           << found->second.error << (found->second.asymptotic ? "" : " (!)");
      return text.str();
    };
    out << std::scientific << std::setprecision(6);
    out << "results:\n"
        << "  dofs " << results.n_dofs << ", cells " << results.n_cells
        << ", bodies " << results.n_bodies << "\n"
        << "  applied load " << force_unit << "           "
        << list(results.applied_load, [](const double f) { return f; }) << "\n";
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
        << bar("energy") << "\n"
        << "  max |u| [m]                  " << results.max_displacement
        << "\n";
    for (const auto &[id, range] : results.stress_yy_range)
      out << "  tau_yy [Pa] in " << std::left << std::setw(14)
          << materials[id].name << std::right << " ["
          << shown_stress(range.first)
          << bar(materials[id].name + ": tau_yy min") << ", "
          << shown_stress(range.second)
          << bar(materials[id].name + ": tau_yy max") << "]\n";
    if (dim == 3)
      for (const auto &[id, value] : results.von_mises_max)
        out << "  max von Mises [Pa] in " << std::left << std::setw(14)
            << materials[id].name << std::right << " " << shown_stress(value)
            << bar(materials[id].name + ": von Mises max") << "\n";
    for (const auto &i : results.interfaces)
      out << "  contact '" << i.name << "': " << i.n_active << " of "
          << i.n_pairs << " pairs active, force "
          << (dim == 2 ? "[N/m] " : "[N] ") << i.force
          << bar("interface " + i.name + ": force") << ", peak pressure [Pa] "
          << i.max_pressure << bar("interface " + i.name + ": peak pressure")
          << (dim == 2 ? ", contact length [m] " : ", contact area [m^2] ")
          << i.contact_length << bar("interface " + i.name + ": contact length")
          << "\n";
    // What the bars rest on, once.
    if (!output_writer.test_mode() && !error_estimates.empty())
      {
        out << "  error bars (+-): estimated discretisation errors of this "
               "mesh (summary.json's error_estimates says how each was "
               "made): strain recovery for the energy and the stress "
               "extremes, goal-oriented for frictionless peak pressures and "
               "forces, one slave spacing per contact edge for the lengths, "
               "else from the run's meshes";
        bool flagged = false;
        for (const auto &[name, estimate] : error_estimates)
          flagged =
            flagged || (std::isfinite(estimate.error) && !estimate.asymptotic);
        if (flagged)
          out << "; (!): not in the asymptotic range or not converging, a "
                 "conservative bar";
        out << "\n";
      }
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



#define KNEE_CONTACT_INSTANTIATE(dim)                        \
  template void ContactProblem<dim>::write_result_set(       \
    const Results<dim> &,                                    \
    const std::vector<std::vector<CycleRecord>> &,           \
    TimerOutput &);                                          \
  template unsigned int ContactProblem<dim>::run_load_cases( \
    const Results<dim> &,                                    \
    const std::vector<std::vector<CycleRecord>> &,           \
    TimerOutput &);                                          \
  template void ContactProblem<dim>::print_results(const Results<dim> &) const;
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
