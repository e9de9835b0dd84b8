// The cycles of a run: mesh, setup, assembly, contact solve and errors per
// refinement cycle (ContactProblem's orchestration, split from problem.cc
// by job as ASPECT splits its Simulator).
#include <knee_contact/base/input.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/base/progress.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/core/scene_checks.h>
#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/rigid_modes.h>

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/sparse_direct.h>

#include <deal.II/numerics/rtree.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iomanip>
#include <iostream>
#include <iterator>
#include <map>
#include <new>

namespace knee_contact
{
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
    Progress                 progress(
      log(), Refinement::name(strategy) + " cycle", n_cycles, true, 0);
    previous_contact.clear();
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

        double coarse_start_time = 0;
        if (cycle == 0 && active_set_solver.coarse_start_levels() > 0 &&
            !contact_interfaces.interfaces().empty())
          timed("coarse start", [&]() {
            coarse_start_time =
              coarse_start(active_set_solver.coarse_start_levels());
          });
        bool resolved = false;
        timed("mesh", [&]() {
          // A mesh that may be distributed is made anew at each uniform
          // cycle's level (a fully distributed mesh cannot be refined),
          // by rank 0 alone.
          const bool distributable = may_distribute(strategy);
          if (cycle == 0 || distributable ||
              (strategy == Refinement::Strategy::global &&
               mesh_input.remeshes(triangulation)))
            {
              if (distributable)
                make_distributable_mesh(cycle, strategy);
              else
                make_mesh(cycle);
            }
          else
            {
              // A refined mesh keeps its pose; its new vertices would lie
              // where the scene's manifolds put them unmoved.
              AssertThrow(motions.empty(),
                          ExcMessage(
                            "Load cases/Motion: moved bodies need a mesh "
                            "made anew in each refinement cycle (a Gmsh "
                            ".geo file with global refinement) or a single "
                            "cycle; this scene refines its mesh"));
              resolved = !refinement.refine(strategy,
                                            triangulation,
                                            access(),
                                            goal_indicator());
              check_cells(triangulation);
            }
          // make_distributable_mesh() checked and decided.
          if (!distributable)
            {
              scene_checks::check_finite_data(triangulation,
                                              materials,
                                              boundary_conditions);
              distributed_reason.clear();
            }
        });
        if (resolved)
          {
            // The previous cycle's mesh, solution and results stand.
            std::cout << record.strategy << " cycle " << cycle
                      << ": the error estimate is round-off (below "
                      << Refinement::round_off_level
                      << " of the energy norm): cycle " << cycle - 1
                      << "'s mesh represents the solution; no more cycles"
                      << std::endl;
            break;
          }
        timed("setup", [&]() { setup_system(); });
        std::cout << record.strategy << " cycle " << cycle << ": " << n_cells()
                  << " cells, " << dof_handler.n_dofs() << " dofs, " << n_bodies
                  << " bodies, " << contact_pairs.size() << " contact pairs"
                  << (distributed
                        ? ", the mesh distributed over " +
                            std::to_string(parallel::n_ranks()) + " ranks"
                        : std::string())
                  << std::endl;
        timed("assembly",
              [&]() { assemble_system(!previous_contact.empty()); });
        timed("solve", [&]() {
          // Warm start on a refined mesh: pairs within the previous contact
          // zone start active (the loop corrects the guess).
          solve_contact(previous_zone_guess(), true);
          if (coarse_start_time > 0)
            solver_figures["coarse_start"] = coarse_start_time;
        });
        timed("postprocess", [&]() {
          results       = current_results();
          record.errors = verification.compute_errors(
            dof_handler, displacement, materials, contact_pairs, results);
        });

        keep_contact_zone();
        record.n_cells        = n_cells();
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
        record.quantities = cycle_quantities(results);
        {
          // The error bars of this sequence so far (the finest mesh's).
          std::vector<Quantities> cycles;
          std::vector<double>     n_dofs;
          for (const auto &r : records)
            {
              cycles.push_back(r.quantities);
              n_dofs.push_back(r.n_dofs);
            }
          cycles.push_back(record.quantities);
          n_dofs.push_back(record.n_dofs);
          // The previous mesh's bars (its goal-oriented ones are checked
          // against the change since).
          const std::map<std::string, ErrorEstimate> previous =
            records.empty() ? std::map<std::string, ErrorEstimate>()
                            : error_estimates;
          error_estimates = estimate_errors(cycles, n_dofs, dim);
          // The bars of this mesh alone, the estimate's phase: the peak
          // pressures' goal-oriented ones (one more solve with the
          // factorisation of this mesh) and the energy's from the same
          // strain recovery, with Roache's safety factor 1.25 (measured
          // effectivity of eta^2 on the knees and the two rings after two
          // cycles: 0.92 to 3.8; the mesh sequence's differences gave 0.95
          // to 43 on adaptive meshes, whose energies do not converge
          // monotonically).
          {
            TimerOutput::Scope scope(timer, "error estimate");
            Timer              clock;
            // What the solve freed goes back first: the estimate's
            // influences and recoveries did not fit into it and set the
            // peak of one process and of every rank on four at 1e6 dofs
            // (one process 3 834 -> 3 567 MB with both trims, the end of
            // the run on four ranks 1 146-1 202 -> 1 077-1 097 a rank;
            // doc/parallel.md).
            memory::return_free_heap();
            record.recovered_energy_error =
              estimate_mesh_errors(results,
                                   strategy == Refinement::Strategy::global,
                                   previous);
            error_estimates["energy"] =
              recovered_energy_estimate(record.energy,
                                        record.recovered_energy_error);
            record.wall_time["error estimate"] += clock.wall_time();
            record.total_time += clock.wall_time();
          }
          const auto relative = [&](const std::string &name) {
            const auto found = error_estimates.find(name);
            return found == error_estimates.end()
                     ? std::numeric_limits<double>::quiet_NaN()
                     : found->second.error / std::abs(found->second.value);
          };
          record.estimated_peak_pressure_error = relative("peak pressure");
          record.estimated_energy_error        = relative("energy");
        }
        if (!output_writer.test_mode())
          std::cout << std::setprecision(7) << "   " << record.n_dofs
                    << " dofs: peak pressure " << record.peak_pressure
                    << ", energy " << record.energy << ", " << record.total_time
                    << " s" << std::endl;
        record.peak_memory = memory::peak_resident_MB();
        records.push_back(record);
        if (!contact_solution.converged)
          break;
        if (refinement.target_error > 0)
          {
            const ErrorEstimate &target =
              error_estimates.at(refinement.target_quantity);
            const double relative = target.error / std::abs(target.value);
            double       time     = 0;
            for (const auto &r : records)
              time += r.total_time;
            std::cout << std::setprecision(4)
                      << "   target: " << refinement.target_quantity << " "
                      << target.value << " +- " << target.error << " ("
                      << relative << " relative, " << target.basis
                      << "), target " << refinement.target_error;
            // Reached only with a bar a second mesh has checked (a bar
            // from one mesh does not see the error of curved edges on a
            // coarse mesh: the two rings' first mesh, 180 dofs, has a
            // goal-oriented bar of 13 % beside a true error of 116 %) and
            // that is not flagged.
            if (records.size() >= 2 && target.asymptotic &&
                std::isfinite(relative) && relative <= refinement.target_error)
              {
                std::cout << ": reached with " << record.n_dofs << " dofs in "
                          << time << " s" << std::endl;
                break;
              }
            std::cout << (cycle + 1 < n_cycles
                            ? ": refining"
                            : ": NOT reached in the cycles allowed")
                      << std::endl;
            if (cycle + 1 == n_cycles)
              output_writer.warn(
                "Refinement/Target error " +
                input::format(refinement.target_error) + " for '" +
                refinement.target_quantity + "' not reached in " +
                std::to_string(n_cycles) +
                " cycles; raise the number of cycles or the target");
          }
        progress.step_done(cycle, record.total_time);
      }
    return records;
  }



  template <int dim>
  Quantities
  ContactProblem<dim>::cycle_quantities(const Results<dim> &results) const
  {
    Quantities quantities;
    quantities["energy"] = results.energy;
    if (!results.interfaces.empty())
      {
        double peak = 0;
        for (const auto &i : results.interfaces)
          {
            peak = std::max(peak, i.max_pressure);
            quantities["interface " + i.name + ": peak pressure"] =
              i.max_pressure;
            quantities["interface " + i.name + ": force"] = i.force;
            quantities["interface " + i.name + ": contact length"] =
              i.contact_length;
          }
        quantities["peak pressure"] = peak;
      }
    for (const auto &[id, range] : results.stress_yy_range)
      {
        quantities[materials[id].name + ": tau_yy min"] = range.first;
        quantities[materials[id].name + ": tau_yy max"] = range.second;
      }
    for (const auto &[id, value] : results.von_mises_max)
      quantities[materials[id].name + ": von Mises max"] = value;
    return quantities;
  }



  template <int dim>
  void
  ContactProblem<dim>::keep_contact_zone()
  {
    previous_contact.clear();
    for (unsigned int p = 0; p < contact_pairs.size(); ++p)
      if (contact_solution.active[p])
        previous_contact.emplace_back(contact_pairs.points[p].position,
                                      contact_pairs.rows[p].spacing(dim));
  }



  template <int dim>
  std::vector<bool>
  ContactProblem<dim>::previous_zone_guess() const
  {
    // Pairs within a previous active pair's spacing start active (the loop
    // corrects the guess); none known: the loop's own start. The kept
    // pairs' reach as boxes in deal.II's RTree: each pair asks for the
    // boxes it lies in (comparing every pair with every kept one was
    // quadratic: 0.1 s at 1.4e4 x 3e3 pairs).
    std::vector<bool> guess;
    if (previous_contact.empty())
      return guess;
    std::vector<std::pair<BoundingBox<dim>, unsigned int>> reach;
    for (unsigned int k = 0; k < previous_contact.size(); ++k)
      {
        const auto &[position, length] = previous_contact[k];
        Point<dim> low = position, high = position;
        for (unsigned int d = 0; d < dim; ++d)
          {
            low[d] -= length;
            high[d] += length;
          }
        reach.emplace_back(BoundingBox<dim>({low, high}), k);
      }
    const auto tree = pack_rtree(reach);
    guess.assign(contact_pairs.size(), false);
    std::vector<std::pair<BoundingBox<dim>, unsigned int>> near;
    for (unsigned int p = 0; p < contact_pairs.size(); ++p)
      {
        const Point<dim> &x = contact_pairs.points[p].position;
        near.clear();
        tree.query(boost::geometry::index::intersects(x),
                   std::back_inserter(near));
        for (const auto &[box, k] : near)
          if (x.distance(previous_contact[k].first) <=
              previous_contact[k].second)
            guess[p] = true;
      }
    return guess;
  }



  template <int dim>
  double
  ContactProblem<dim>::coarse_start(const unsigned int levels)
  {
    // Nested iteration: the active-set loop needs few iterations from a
    // good guess, and many from the pairs that touch (on the Hertz sphere
    // it releases a ring of pairs per iteration after the first solve
    // pressed the sphere on one point); a mesh with 2^dim times fewer
    // cells per level finds the zone for a fraction of a solve on this one.
    // The coarse meshes' solves take the path the automatic choice finds
    // cheapest for them, whatever the scene asks for the run's own mesh.
    mesh_input.check_coarser_levels(levels);
    Timer      clock;
    const auto path = active_set_solver.linear_solver();
    active_set_solver.set_linear_solver(SolverPath::automatic);
    previous_contact.clear();
    for (int level = -int(levels); level < 0; ++level)
      {
        try
          {
            make_mesh(level);
            setup_system();
            assemble_system(!previous_contact.empty());
            solve_contact(previous_zone_guess(), true);
          }
        catch (const std::exception &exc)
          {
            std::cout << "coarse start level " << level
                      << " skipped: " << input::one_line(exc.what())
                      << std::endl;
            previous_contact.clear();
            break;
          }
        keep_contact_zone();
        std::cout << "coarse start level " << level << ": "
                  << triangulation.n_active_cells() << " cells, "
                  << dof_handler.n_dofs() << " dofs, "
                  << previous_contact.size() << " of " << contact_pairs.size()
                  << " pairs active" << std::endl;
      }
    active_set_solver.set_linear_solver(path);
    return clock.wall_time();
  }



  template <int dim>
  void
  ContactProblem<dim>::solve_contact(const std::vector<bool> &guess,
                                     const bool               new_matrix,
                                     const bool               continue_path)
  {
    const RigidModes<dim> &rigid_modes = *this->rigid_modes;
    std::ostream          &loop_log = contact_pairs.empty() ? quiet : std::cout;
    try
      {
        Timer clock;
        // Along a load path with friction (a further case on the same
        // matrix) each case starts where the previous one ended: a pair
        // sticks where it is, so the tangential rows' gaps become the
        // current tangential jumps, and the slip accumulates. The
        // factorised system stays; it is told that the gaps changed.
        const bool path_step = !new_matrix && contact_pairs.frictional();
        if (path_step)
          {
            hold_tangential_rows_at(displacement);
            contact_system->gaps_changed();
          }
        // A new system: made here from C, unless the path took its rows
        // at the assembly (assemble_system()).
        if (new_matrix && !contact_system)
          make_solver();
        if (!contact_pairs.frictional())
          {
            contact_system->set_rhs(system_rhs);
            contact_solution = active_set_solver.solve(*contact_system,
                                                       system_rhs.linfty_norm(),
                                                       constraints,
                                                       contact_pairs.rows,
                                                       rigid_modes,
                                                       guess,
                                                       loop_log);
          }
        else
          {
            std::vector<double> accumulated =
              path_step || continue_path
                ? contact_solution.accumulated_slip
                : std::vector<double>(contact_pairs.size(), 0.);
            accumulated.resize(contact_pairs.size(), 0.);
            std::vector<FrictionBound> bounds(contact_pairs.size());
            for (unsigned int p = 0; p < contact_pairs.size(); ++p)
              {
                const ContactRow       &row = contact_pairs.rows[p];
                const ContactInterface &interface =
                  contact_interfaces.interfaces()[row.interface];
                if (interface.friction == Friction::coulomb)
                  bounds[p] = {true, interface.friction_coefficient, {}};
                else if (interface.friction == Friction::tresca)
                  bounds[p] = {false, interface.tresca_bound * row.length, {}};
                bounds[p].stick =
                  stick_coefficients<dim>(contact_pairs.points[p].normal,
                                          contact_pairs.points[p].tangents);
              }
            contact_solution =
              active_set_solver.solve_with_friction(*contact_system,
                                                    system_rhs,
                                                    constraints,
                                                    friction_rows,
                                                    bounds,
                                                    rigid_modes,
                                                    guess,
                                                    loop_log);
            if (contact_solution.status.size() == contact_pairs.size())
              {
                for (unsigned int p = 0; p < contact_pairs.size(); ++p)
                  if (contact_solution.status[p] ==
                      ContactSolution::Status::slip)
                    accumulated[p] += magnitude(contact_solution.slip[p]);
                contact_solution.accumulated_slip = std::move(accumulated);
              }
          }
        contact_system->solution(displacement);
        solver_figures["contact_solve"] =
          clock.wall_time() + (new_matrix ? solver_figures["choice"] : 0.);
        for (const auto &[name, value] : contact_system->statistics())
          solver_figures[name] = value;
        if (new_matrix && active_set_solver.measure_reference() &&
            !contact_pairs.frictional())
          {
            // One linear solve by the same path: CHOLMOD for the direct
            // paths, a new hierarchy and CG from zero for the iterative one.
            Vector<double> x;
            auto          *iterative =
              dynamic_cast<IterativeContactSystem *>(contact_system.get());
            solver_figures["reference_solve"] =
              iterative ? iterative->reference_solve(contact_solution.active, x)
                        : reference_solve(system_matrix,
                                          system_rhs,
                                          constraints,
                                          contact_pairs.rows,
                                          contact_solution.active,
                                          x);
            if (iterative)
              solver_figures["reference_krylov_iterations"] =
                iterative->statistics()["reference_krylov_iterations"];
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
  void
  ContactProblem<dim>::hold_tangential_rows_at(
    const Vector<double>              &u,
    const std::vector<Tensor<1, dim>> &offsets)
  {
    // friction_rows: N, T_j and S_k = sum_i c[k][i] [N; T]_i
    // (FrictionRowLayout, stick_coefficients()).
    const unsigned int      n = contact_pairs.size();
    const FrictionRowLayout at{n, dim};
    for (unsigned int p = 0; p < n; ++p)
      {
        const StickCoefficients c =
          stick_coefficients<dim>(contact_pairs.points[p].normal,
                                  contact_pairs.points[p].tangents);
        for (unsigned int j = 0; j + 1 < dim; ++j)
          {
            ContactRow  &t_row = friction_rows[at.tangential(j, p)];
            const double shift =
              t_row.jump(u) - t_row.gap -
              (offsets.empty()
                 ? 0.
                 : contact_pairs.points[p].tangents[j] * offsets[p]);
            t_row.gap += shift;
            t_row.reduced_gap += shift;
            for (unsigned int k = 0; k < dim; ++k)
              {
                ContactRow &s_row = friction_rows[at.stick(k, p)];
                s_row.gap += c[k][1 + j] * shift;
                s_row.reduced_gap += c[k][1 + j] * shift;
              }
          }
      }
  }



  template <int dim>
  void
  ContactProblem<dim>::assemble_system(const bool warm_start)
  {
    // The previous system (its factor) goes before the new one is made.
    contact_system.reset();
    system_matrix.clear();
    Timer                          clock;
    const ElasticityAssembler<dim> assembler(materials, boundary_conditions);
    if (distributed)
      {
        // The path that runs on the distributed mesh: C's rows from each
        // rank's cells, d whole (each rank's cells summed over the ranks).
        solver_plan = plan_contact_system(*distributed_pattern,
                                          rows_for_solver(),
                                          distributed_reason);
        solver_plan.figures["choice"] = clock.wall_time();
        assembler.assemble_rhs(dof_handler, system_rhs);
        make_solver();
        return;
      }
    solver_plan = plan_contact_system(active_set_solver.linear_solver(),
                                      sparsity_pattern,
                                      system_matrix,
                                      constraints,
                                      rows_for_solver(),
                                      active_set_solver.direct_factor(),
                                      warm_start);
    solver_plan.figures["choice"] = clock.wall_time();
    if (!solver_plan.rows_only)
      {
        system_matrix.reinit(sparsity_pattern);
        assembler.assemble(dof_handler, system_matrix, system_rhs);
        return;
      }
    // Each rank assembles the rows its path holds (C whole, 8 bytes per
    // entry on every rank, is never made) and d whole (a pass over the
    // cells without their matrices). The choice is timed apart: the
    // assembly phase holds it, and contact_solve counts it.
    assembler.assemble_rhs(dof_handler, system_rhs);
    make_solver();
  }



  template <int dim>
  void
  ContactProblem<dim>::make_solver()
  {
    std::ostream &log =
      output_writer.test_mode() || contact_pairs.empty() ? quiet : std::cout;
    const IterativeContactSystem::RowAssembly rows = [this](const auto &wanted,
                                                            const auto &add) {
      ElasticityAssembler<dim>(materials, boundary_conditions)
        .assemble_cells(dof_handler, wanted, add);
    };
    const bool   rows_only = solver_plan.rows_only;
    SolverChoice choice =
      distributed ? make_contact_system(std::move(solver_plan),
                                        *distributed_pattern,
                                        rows,
                                        constraints,
                                        rows_for_solver(),
                                        *rigid_modes,
                                        active_set_solver.krylov_settings(),
                                        log)
                  : make_contact_system(std::move(solver_plan),
                                        sparsity_pattern,
                                        system_matrix,
                                        rows_only ? &rows : nullptr,
                                        constraints,
                                        rows_for_solver(),
                                        *rigid_modes,
                                        active_set_solver.krylov_settings(),
                                        log);
    contact_system = std::move(choice.system);
    solver_name    = std::move(choice.name);
    solver_figures = std::move(choice.figures);
  }



  template <int dim>
  std::vector<bool>
  ContactProblem<dim>::move_to_case(const double t_from, const double t_to)
  {
    // A pair is its interface's slave vertex: the key that survives the
    // new search (the slave vertex may now face another master face, or
    // none).
    std::map<std::pair<unsigned int, types::global_dof_index>, unsigned int>
      previous_pair;
    for (unsigned int p = 0; p < contact_pairs.size(); ++p)
      previous_pair[{contact_pairs.rows[p].interface,
                     contact_pairs.points[p].slave_dofs[0]}] = p;
    const ContactSolution previous = contact_solution;
    // The previous displacements in this case's frame.
    Vector<double> previous_u = displacement;
    motions.rotate_displacements(dof_handler, t_from, t_to, previous_u);

    motions.move(triangulation, t_from, t_to);
    setup_system();
    // The same cells and element: the same dof numbering.
    AssertThrow(dof_handler.n_dofs() == previous_u.size(), ExcInternalError());
    assemble_system(true);

    const unsigned int  n = contact_pairs.size();
    std::vector<bool>   guess(n, false);
    std::vector<double> accumulated(n, 0.);
    for (unsigned int p = 0; p < n; ++p)
      {
        const auto found =
          previous_pair.find({contact_pairs.rows[p].interface,
                              contact_pairs.points[p].slave_dofs[0]});
        if (found == previous_pair.end())
          continue;
        const unsigned int q = found->second;
        guess[p]             = q < previous.active.size() && previous.active[q];
        if (q < previous.accumulated_slip.size())
          accumulated[p] = previous.accumulated_slip[q];
      }
    if (contact_pairs.frictional())
      {
        // Each pair's rigid motion since the previous case: that of its
        // slave vertex against the master point it now faces. The master
        // side moves as the row's largest entry of another motion than the
        // slave's (a row's entries are the slave vertex, perhaps slave
        // neighbours, and the master face's vertices); none: both sides
        // move alike.
        const std::vector<unsigned int> motion_of_dof =
          motions.motion_of_dofs(dof_handler);
        std::vector<Tensor<1, dim>> offsets(n);
        for (unsigned int p = 0; p < n; ++p)
          {
            const ContactPoint<dim> &point = contact_pairs.points[p];
            const unsigned int       slave = motion_of_dof[point.slave_dofs[0]];
            unsigned int             master  = slave;
            double                   largest = 0;
            for (const auto &[dof, value] : contact_pairs.rows[p].row)
              if (motion_of_dof[dof] != slave && std::abs(value) > largest)
                {
                  largest = std::abs(value);
                  master  = motion_of_dof[dof];
                }
            offsets[p] = motions.relative_motion(
              slave, master, point.position, t_from, t_to);
          }
        hold_tangential_rows_at(previous_u, offsets);
      }
    contact_solution.accumulated_slip = std::move(accumulated);
    return guess;
  }



  template <int dim>
  Results<dim>
  ContactProblem<dim>::current_results() const
  {
    return compute_results(access());
  }



  template <int dim>
  ProblemAccess<dim>
  ContactProblem<dim>::access() const
  {
    // C's product: the matrix's, or the path's where it holds C's rows
    // and C whole is not made (the iterative path on several ranks).
    const auto product = [this](Vector<double> &y, const Vector<double> &x) {
      if (contact_system && contact_system->holds_stiffness())
        contact_system->stiffness_product(y, x);
      else
        system_matrix.vmult(y, x);
    };
    return {dof_handler,
            body_of_cell,
            product,
            system_rhs,
            displacement,
            materials,
            boundary_conditions,
            contact_interfaces,
            contact_pairs,
            contact_solution};
  }



  template <int dim>
  void
  ContactProblem<dim>::set_load_parameter(const double t)
  {
    load_parameter = t;
    materials.set_load_parameter(t);
    boundary_conditions.set_load_parameter(t);
    verification.set_load_parameter(t);
  }



#define KNEE_CONTACT_INSTANTIATE(dim)                                         \
  template std::vector<CycleRecord> ContactProblem<dim>::run_cycles(          \
    const Refinement::Strategy, TimerOutput &, Results<dim> &);               \
  template void ContactProblem<dim>::solve_contact(const std::vector<bool> &, \
                                                   const bool,                \
                                                   const bool);               \
  template std::vector<bool> ContactProblem<dim>::move_to_case(const double,  \
                                                               const double); \
  template Results<dim>      ContactProblem<dim>::current_results() const;    \
  template Quantities        ContactProblem<dim>::cycle_quantities(           \
    const Results<dim> &) const;                                       \
  template void ContactProblem<dim>::set_load_parameter(const double);
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
