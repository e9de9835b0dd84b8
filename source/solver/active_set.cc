#include <knee_contact/base/input.h>
#include <knee_contact/base/progress.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/row_multipliers.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <deal.II/dofs/dof_tools.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>

namespace knee_contact
{
  void
  ActiveSetSolver::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Contact");
    prm.add_parameter("Maximum active set iterations",
                      max_iterations,
                      "Stop with converged = false after this many "
                      "iterations.",
                      Patterns::Integer(1));
    prm.add_parameter("Active set constant",
                      c_relative,
                      "c of the active-set test lambda_p + c ((A x)_p - g_p) "
                      "> 0, in units of the largest Young's modulus (step-42 "
                      "uses 100 E).",
                      Patterns::Double(0));
    prm.add_parameter("Tolerance",
                      tolerance,
                      "Converged when the active set repeats and the "
                      "relative complementarity residual max_p |min(lambda_p "
                      "/ max lambda, (g_p - (A x)_p) / max |u|)| is below "
                      "this (max |u| over the contact unknowns).",
                      Patterns::Double(0));
    prm.add_parameter("Cycle safeguard",
                      safeguard,
                      "When the active set returns to an earlier set, go on "
                      "releasing at most one pair per iteration (the most "
                      "negative lambda) while adding every penetrating pair; "
                      "false: stop with converged = false.");
    std::vector<std::pair<std::string, LinearSolver>> paths;
    for (const LinearSolver path : {LinearSolver::automatic,
                                    LinearSolver::condensed,
                                    LinearSolver::sparse,
                                    LinearSolver::iterative,
                                    LinearSolver::step41})
      paths.emplace_back(solver_path_name(path), path);
    input::add_selection(
      prm,
      "Solver",
      solver,
      paths,
      "automatic: estimate the time and memory of the condensed and sparse "
      "paths before allocating and take the cheaper that fits (the log and "
      "summary.json say which and why); condensed: factorise once per mesh "
      "with the contact unknowns last and run the loop on their dense Schur "
      "complement (cheapest where the contact unknowns are few); sparse: one "
      "CHOLMOD analysis per mesh, one numeric factorisation per active set "
      "(memory of the sparse factor only); iterative: CG preconditioned by "
      "Trilinos ML's AMG with the rigid motions as near null space, memory "
      "linear in the dofs (the path for large 3D meshes); step-41: condense "
      "and factorise the whole system with UMFPACK in every iteration (the "
      "first version's path, kept for comparison).");
    input::add_selection(
      prm,
      "Direct factor",
      factor,
      std::vector<std::pair<std::string, DirectFactor>>{
        {direct_factor_name(DirectFactor::automatic), DirectFactor::automatic},
        {direct_factor_name(DirectFactor::cholmod), DirectFactor::cholmod},
        {direct_factor_name(DirectFactor::mumps), DirectFactor::mumps}},
      "The sparse path's factor. CHOLMOD: supernodal Cholesky, the whole "
      "factor on every rank; MUMPS: multifrontal LDL^T in the same order "
      "with the factor and its work divided over the ranks of an mpirun "
      "(memory per rank about 1/N of the factor), and on one process the "
      "sparse path whatever the automatic choice (doc/parallel.md); "
      "automatic: MUMPS on more than one rank, CHOLMOD on one.");
    prm.add_parameter("Krylov tolerance",
                      krylov.tolerance,
                      "Iterative path: each accepted solve stops at this "
                      "residual relative to its right hand side (earlier "
                      "iterations stop sooner: doc/performance.md).",
                      Patterns::Double(1e-15, 1e-3));
    prm.add_parameter("Krylov iterations",
                      krylov.max_iterations,
                      "Iterative path: CG iterations allowed per solve; "
                      "more ends the run with an error.",
                      Patterns::Integer(1));
    prm.add_parameter(
      "Coarse start levels",
      coarse_levels,
      "Before the first cycle, solve the contact problem on the mesh this "
      "many levels coarser (a .geo of tetrahedra meshed by gmsh at 2^k "
      "times its size, else k fewer Global refinements) and start the loop "
      "from its contact zone; the loop's iterations then mostly fall away "
      "(doc/performance.md). 0: start from the pairs that touch.",
      Patterns::Integer(0, 3));
    prm.add_parameter("Reference solve",
                      reference_solve,
                      "After the contact solve, time one linear solve of the "
                      "same system with the final active set held fixed "
                      "(CHOLMOD, METIS ordering: the fastest linear solver "
                      "of the project) and compare its solution; the "
                      "benchmark's reference.");
    prm.leave_subsection();
  }



  void
  ActiveSetSolver::check_parameters(const double max_youngs_modulus,
                                    const double min_youngs_modulus)
  {
    c         = c_relative * max_youngs_modulus;
    e_minimum = min_youngs_modulus;
    AssertThrow(c > 0, ExcMessage("Contact/Active set constant must be > 0"));
  }



  void
  ActiveSetSolver::make_constraints(const AffineConstraints<double> &base,
                                    const std::vector<ContactRow>   &pairs,
                                    const std::vector<bool>         &active,
                                    AffineConstraints<double> &constraints)
  {
    // An active row a'_p . x = g'_p over dofs free of Gamma_u/Gamma_o, solved
    // for the eliminated dof j: x_j = (g'_p - sum_{k != j} a'_pk x_k) / a'_pj.
    constraints.clear();
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (active[p])
        {
          const ContactRow &pair = pairs[p];
          double            a_j  = 0;
          for (const auto &[dof, a] : pair.reduced_row)
            if (dof == pair.eliminated)
              a_j = a;
          constraints.add_line(pair.eliminated);
          for (const auto &[dof, a] : pair.reduced_row)
            if (dof != pair.eliminated)
              constraints.add_entry(pair.eliminated, dof, -a / a_j);
          constraints.set_inhomogeneity(pair.eliminated,
                                        pair.reduced_gap / a_j);
        }
    constraints.merge(
      base, AffineConstraints<double>::MergeConflictBehavior::left_object_wins);
    constraints.close();
  }



  std::vector<double>
  ActiveSetSolver::multipliers(const Vector<double>            &residual,
                               const AffineConstraints<double> &base,
                               const std::vector<ContactRow>   &pairs,
                               const std::vector<bool>         &active)
  {
    // Equations at the eliminated dofs j_p of the active pairs:
    //   sum_q lambda_q a'_q(j_p) = (C0^T r)(j_p),
    // (C0^T r)(j) = r_j + sum over Gamma_u/Gamma_o lines x_i = c_ij x_j + ..
    // of c_ij r_i (RowMultipliers).
    return RowMultipliers(base, pairs, active)(residual);
  }



  namespace
  {
    /**
     * The pattern of every active set's condensed system (see the comment
     * in the code), for both front ends of make_sparsity_pattern():
     * @p for_each_row(f) calls f(i, columns) for the rows of the mesh's
     * pattern to expand (all of them, or this rank's), @p add(a, columns)
     * adds sorted columns to row a, @p adds_row(a) says whether this
     * pattern holds row a (the springs' rows).
     */
    void
    expand_pattern(
      const types::global_dof_index n,
      const std::function<void(
        const std::function<void(const types::global_dof_index,
                                 const std::vector<types::global_dof_index> &)>
          &)>                      &for_each_row,
      const std::function<void(const types::global_dof_index,
                               const std::vector<types::global_dof_index> &)>
                                                               &add,
      const std::function<bool(const types::global_dof_index)> &adds_row,
      const AffineConstraints<double>                          &base,
      const std::vector<ContactRow>                            &pairs,
      const bool                                                cycles_allowed,
      const std::vector<std::vector<unsigned int>>             &spring_rows)
    {
      // One sparsity pattern serves every active set. Condensing a set of
      // lines couples each dof i with the dofs its line refers to after
      // chains are resolved, and which chains exist depends on the active set
      // (a hanging node refers to a slave dof, which refers to master dofs
      // only while its pair is active). So E(i) is the transitive closure of
      // the one-level entries R(i) (Gamma_u/Gamma_o/hanging-node line, or the
      // reduced row of the pair eliminating i), and an entry (i, j) of the
      // mesh's pattern needs E(i) x E(j).
      std::map<types::global_dof_index, std::set<types::global_dof_index>>
        one_level;
      for (const auto &line : base.get_lines())
        for (const auto &entry : line.entries)
          one_level[line.index].insert(entry.first);
      for (const auto &pair : pairs)
        if (pair.eliminated != numbers::invalid_dof_index)
          for (const auto &entry : pair.reduced_row)
            if (entry.first != pair.eliminated)
              one_level[pair.eliminated].insert(entry.first);
      std::map<types::global_dof_index, std::vector<types::global_dof_index>>
                                        expansion;
      std::set<types::global_dof_index> in_progress;
      const std::function<const std::vector<types::global_dof_index> &(
        types::global_dof_index)>
        closure = [&](const types::global_dof_index i)
        -> const std::vector<types::global_dof_index> & {
        const auto known = expansion.find(i);
        if (known != expansion.end())
          return known->second;
        // Lines that refer to each other in a cycle cannot be constraints; the
        // elimination in make_pairs() is meant to prevent it among rows that
        // can be active together. With friction the normal and tangential
        // rows of a pair may refer to each other, but they are never active
        // together (a sticking pair is held by its X and Y rows): there the
        // closure is the set of dofs reachable from i.
        if (!in_progress.insert(i).second)
          {
            if (!cycles_allowed)
              throw std::logic_error("the contact rows eliminate dofs that "
                                     "refer to each other in a cycle (dof " +
                                     std::to_string(i) + ")");
            std::set<types::global_dof_index>    reached = {i};
            std::vector<types::global_dof_index> stack   = {i};
            while (!stack.empty())
              {
                const auto k = stack.back();
                stack.pop_back();
                const auto it = one_level.find(k);
                if (it != one_level.end())
                  for (const auto e : it->second)
                    if (reached.insert(e).second)
                      stack.push_back(e);
              }
            return expansion[i] =
                     std::vector<types::global_dof_index>(reached.begin(),
                                                          reached.end());
          }
        std::set<types::global_dof_index> dofs = {i};
        const auto                        it   = one_level.find(i);
        if (it != one_level.end())
          for (const auto e : it->second)
            {
              const auto &sub = closure(e);
              dofs.insert(sub.begin(), sub.end());
            }
        return expansion[i] =
                 std::vector<types::global_dof_index>(dofs.begin(), dofs.end());
      };
      for (const auto &entry : one_level)
        closure(entry.first);

      // Each dof's expansion, by index (a map lookup per entry of the mesh's
      // pattern took 8.3 s at 1e6 dofs); none: the dof itself.
      std::vector<const std::vector<types::global_dof_index> *> expansion_of(
        n, nullptr);
      for (const auto &[i, e] : expansion)
        expansion_of[i] = &e;

      // A spring k w w^T couples every dof of its rows' reduced rows with
      // every other, and each of them expands as a line of the mesh's
      // pattern does.
      for (const auto &group : spring_rows)
        {
          std::set<types::global_dof_index> dofs;
          for (const unsigned int r : group)
            for (const auto &entry : pairs[r].reduced_row)
              if (const auto *e = expansion_of[entry.first])
                dofs.insert(e->begin(), e->end());
              else
                dofs.insert(entry.first);
          const std::vector<types::global_dof_index> sorted(dofs.begin(),
                                                            dofs.end());
          for (const auto a : sorted)
            if (adds_row(a))
              add(a, sorted);
        }
      // Row by row, each row's columns expanded, sorted and added at once.
      std::vector<types::global_dof_index> expanded;
      for_each_row([&](const types::global_dof_index               i,
                       const std::vector<types::global_dof_index> &columns) {
        expanded.clear();
        bool expanded_columns = false;
        for (const auto j : columns)
          if (const auto *ej = expansion_of[j])
            {
              expanded.insert(expanded.end(), ej->begin(), ej->end());
              expanded_columns = true;
            }
          else
            expanded.push_back(j);
        if (expanded_columns ||
            !std::is_sorted(expanded.begin(), expanded.end()))
          {
            std::sort(expanded.begin(), expanded.end());
            expanded.erase(std::unique(expanded.begin(), expanded.end()),
                           expanded.end());
          }
        if (const auto *ei = expansion_of[i])
          for (const auto a : *ei)
            add(a, expanded);
        else
          add(i, expanded);
      });
    }
  } // namespace



  void
  ActiveSetSolver::make_sparsity_pattern(
    const DynamicSparsityPattern                 &mesh_pattern,
    const AffineConstraints<double>              &base,
    const std::vector<ContactRow>                &pairs,
    SparsityPattern                              &sparsity_pattern,
    const bool                                    cycles_allowed,
    const std::vector<std::vector<unsigned int>> &spring_rows)
  {
    DynamicSparsityPattern               dsp(mesh_pattern.n_rows());
    std::vector<types::global_dof_index> columns;
    expand_pattern(
      mesh_pattern.n_rows(),
      [&](const auto &f) {
        for (types::global_dof_index i = 0; i < mesh_pattern.n_rows(); ++i)
          {
            columns.clear();
            for (auto it = mesh_pattern.begin(i); it != mesh_pattern.end(i);
                 ++it)
              columns.push_back(it->column());
            f(i, columns);
          }
      },
      [&](const types::global_dof_index               a,
          const std::vector<types::global_dof_index> &sorted) {
        dsp.add_entries(a, sorted.begin(), sorted.end(), true);
      },
      [](const types::global_dof_index) { return true; },
      base,
      pairs,
      cycles_allowed,
      spring_rows);
    sparsity_pattern.copy_from(dsp);
  }



  void
  ActiveSetSolver::make_sparsity_pattern(
    const TrilinosWrappers::SparsityPattern      &mesh_pattern,
    const AffineConstraints<double>              &base,
    const std::vector<ContactRow>                &pairs,
    TrilinosWrappers::SparsityPattern            &sparsity_pattern,
    const bool                                    cycles_allowed,
    const std::vector<std::vector<unsigned int>> &spring_rows)
  {
    // Each rank expands its rows of the mesh's pattern into a pattern of
    // its own rows; a row of another rank that a line's expansion reaches
    // is sent to its owner here, so that Epetra's graph is made from owned
    // rows alone. Given such rows itself, Epetra's FE graph sends them in
    // its GlobalAssemble() and keeps that export's buffers as long as the
    // graph lives: 21 of the 35 MB a rank's pattern held at 2.3e5 dofs on
    // four ranks (heaptrack, doc/parallel.md), through every solve.
    const MPI_Comm comm  = mesh_pattern.get_mpi_communicator();
    const IndexSet owned = mesh_pattern.locally_owned_range_indices();
    // (deal.II makes Epetra's graph from a pattern of one range of rows.)
    AssertThrow(owned.is_contiguous(), ExcInternalError());
    DynamicSparsityPattern mine(owned.size(), owned.size(), owned);
    std::map<types::global_dof_index, std::vector<types::global_dof_index>>
                           others;
    const Epetra_CrsGraph &graph = mesh_pattern.trilinos_sparsity_pattern();
    std::vector<types::global_dof_index> columns;
    expand_pattern(
      owned.size(),
      [&](const auto &f) {
        for (int local = 0; local < graph.NumMyRows(); ++local)
          {
            int  length  = 0;
            int *indices = nullptr;
            graph.ExtractMyRowView(local, length, indices);
            columns.clear();
            for (int k = 0; k < length; ++k)
              columns.push_back(graph.ColMap().GID(indices[k]));
            f(graph.RowMap().GID(local), columns);
          }
      },
      [&](const types::global_dof_index               a,
          const std::vector<types::global_dof_index> &sorted) {
        if (owned.is_element(a))
          mine.add_entries(a, sorted.begin(), sorted.end(), true);
        else
          {
            auto &row = others[a];
            row.insert(row.end(), sorted.begin(), sorted.end());
          }
      },
      [&](const types::global_dof_index a) { return owned.is_element(a); },
      base,
      pairs,
      cycles_allowed,
      spring_rows);

    // Each other row to its owner, as (row, length, columns...).
    const std::vector<IndexSet> owned_by =
      Utilities::MPI::all_gather(comm, owned);
    std::map<unsigned int, std::vector<types::global_dof_index>> sent;
    for (auto &[row, cols] : others)
      {
        std::sort(cols.begin(), cols.end());
        cols.erase(std::unique(cols.begin(), cols.end()), cols.end());
        const auto owner =
          std::find_if(owned_by.begin(), owned_by.end(), [&](const auto &set) {
            return set.is_element(row);
          });
        AssertThrow(owner != owned_by.end(), ExcInternalError());
        auto &message = sent[owner - owned_by.begin()];
        message.push_back(row);
        message.push_back(cols.size());
        message.insert(message.end(), cols.begin(), cols.end());
      }
    others.clear();
    for (const auto &[from, message] : Utilities::MPI::some_to_some(comm, sent))
      for (std::size_t k = 0; k < message.size(); k += 2 + message[k + 1])
        mine.add_entries(message[k],
                         message.begin() + k + 2,
                         message.begin() + k + 2 + message[k + 1],
                         true);
    sent.clear();
    sparsity_pattern.reinit(owned, owned, mine, comm, false);
  }



  void
  ActiveSetSolver::excess_and_multipliers(
    const StiffnessResidual         &stiffness_residual,
    const Vector<double>            &rhs,
    const Vector<double>            &x,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs,
    const std::vector<bool>         &active,
    std::vector<double>             &excess,
    std::vector<double>             &lambda,
    const std::vector<SpringTerm>   &springs,
    const RowMultipliers            *coupled)
  {
    Vector<double> residual(rhs.size());
    stiffness_residual(residual, x, rhs);
    springs::add_forces(springs, x, residual);
    lambda = coupled != nullptr ? (*coupled)(residual)
                                : RowMultipliers(base, pairs, active)(residual);
    excess.resize(pairs.size());
    for (unsigned int p = 0; p < pairs.size(); ++p)
      excess[p] = pairs[p].jump(x) - pairs[p].gap;
  }



  double
  ActiveSetSolver::displacement_scale(const std::vector<ContactRow> &pairs,
                                      const Vector<double>          &x)
  {
    // Over the contact unknowns, as the condensed path sees them.
    double scale = 0;
    for (const auto &pair : pairs)
      if (pair.eliminated != numbers::invalid_dof_index)
        for (const auto &entry : pair.reduced_row)
          scale = std::max(scale, std::abs(x(entry.first)));
    return scale;
  }



  void
  ActiveSetSolver::close_until_held(
    const AffineConstraints<double>         &base,
    const std::vector<ContactRow>           &rows,
    std::vector<unsigned int>                candidates,
    const RigidModeCheck                    &rigid_modes,
    const std::vector<bool>                 &active,
    const std::function<void(unsigned int)> &close)
  {
    std::stable_sort(candidates.begin(),
                     candidates.end(),
                     [&rows](const unsigned int a, const unsigned int b) {
                       return rows[a].gap < rows[b].gap;
                     });
    for (std::size_t closed = 0;
         closed < candidates.size() &&
         !rigid_modes.free_motion(base, rows, active).empty();)
      {
        const std::size_t next = std::min(candidates.size(), 2 * closed + 1);
        for (; closed < next; ++closed)
          close(candidates[closed]);
      }
  }



  std::vector<double>
  ActiveSetSolver::first_step_thresholds(const std::vector<ContactRow> &rows,
                                         const std::vector<double>     &excess,
                                         const std::vector<bool> &in_contact)
  {
    // A body held at the few pairs that touch or that close_until_held()
    // closed sinks by their local compliance (a point force's, F / (E h))
    // and penetrates far beyond its contact zone; the loop then peels the
    // zone by about a third per iteration. Only the pairs within
    // first_step_length of the deepest penetration enter first; the next
    // iteration grows the set to the zone of a body no longer held at a
    // point. Measured on the 3D knee along ISO 14243-3
    // (prm/knee_3d_iso_friction.prm, frictionless, first case; the fraction
    // of the deepest penetration a pair had to exceed: the first
    // iteration's set, the iterations; one threshold for both interfaces):
    // at 6.5e4 dofs (a contact zone of 29 pairs) 0: 361, 9; 0.25: 270, 8;
    // 0.5: 175, 7; 0.75: 76, 6; 0.9: 21, 6. At 1.4e5 dofs (55 pairs) 0:
    // 852, 11; 0.75: 201, 7; 0.9: 54, 6. Per interface, as here, the first
    // case with friction (mu = 0.04) and without, 0.9 / 0.97 / 0.99: at
    // 6.5e4 dofs 8 / 9 / 11 and 5 / 6 / 7 iterations; at 1.4e5 12 / 10 / 12
    // and 6 / 6 / 7; at 2.4e5 with friction 12 / 11 / -; the axial-force
    // path (prm/knee_3d_gait_friction.prm) at 1.2e5 dofs 14 / 13 / - and
    // at 2.3e5 16 / 14 / 13 (the damped zone 734 / 342 / 170 pairs for 286):
    // the point's overshoot grows as the mesh is refined, so the finer
    // meshes, where the iterations cost, take the smaller step.
    const unsigned int n = in_contact.size();
    AssertThrow(n <= rows.size() && n <= excess.size(), ExcInternalError());
    // Per interface: the pairs in contact, those that penetrate, the
    // deepest penetration.
    struct Interface
    {
      unsigned int in_contact = 0, penetrating = 0;
      double       deepest = 0;
    };
    std::map<unsigned int, Interface> interfaces;
    for (unsigned int p = 0; p < n; ++p)
      if (rows[p].eliminated != numbers::invalid_dof_index)
        {
          Interface &i = interfaces[rows[p].interface];
          if (in_contact[p])
            ++i.in_contact;
          else if (excess[p] > 0)
            {
              ++i.penetrating;
              i.deepest = std::max(i.deepest, excess[p]);
            }
        }
    std::vector<double> threshold(n, 0.);
    for (unsigned int p = 0; p < n; ++p)
      if (!in_contact[p])
        if (const auto i = interfaces.find(rows[p].interface);
            i != interfaces.end() &&
            i->second.penetrating > first_step_spread * i->second.in_contact)
          threshold[p] = (1 - first_step_length) * i->second.deepest;
    return threshold;
  }



  ContactSolution
  ActiveSetSolver::solve(ContactSystem                   &system,
                         const double                     force_scale_of_load,
                         const AffineConstraints<double> &base,
                         const std::vector<ContactRow>   &pairs,
                         const RigidModeCheck            &rigid_modes,
                         const std::vector<bool>         &guess,
                         std::ostream                    &log) const
  {
    const unsigned int n_pairs = pairs.size();
    ContactSolution    result;
    result.tolerance = tolerance;
    // Start from the guess (the previous load case's or mesh's contact
    // zone) if there is one, else from the pairs that touch (g_p <= 0). A
    // body that
    // only contact holds (a floating femur, a mobile insert) may need more:
    // close the smallest gaps first, doubling their number, until every body is
    // held. The loop below releases any of them whose multiplier is negative.
    result.active.assign(n_pairs, false);
    std::vector<unsigned int> by_gap;
    for (unsigned int p = 0; p < n_pairs; ++p)
      if (pairs[p].eliminated != numbers::invalid_dof_index)
        {
          if (guess.empty() ? pairs[p].gap <= 0 : bool(guess[p]))
            result.active[p] = true;
          else
            by_gap.push_back(p);
        }
    close_until_held(base,
                     pairs,
                     by_gap,
                     rigid_modes,
                     result.active,
                     [&result](const unsigned int p) {
                       result.active[p] = true;
                     });

    std::set<std::vector<bool>> seen;
    std::vector<double>         excesses;
    // Why the loop stops unconverged, once known (see below).
    std::string failure;
    // Whether the solves may stop early while the set changes, and whether
    // one did (the iterative path).
    bool inexact = true, had_inexact_solve = false;
    // The first solve to 1e-2 of the load (see below).
    system.set_accuracy(1e-2);

    for (unsigned int iteration = 1;; ++iteration)
      {
        rigid_modes.check(
          base,
          pairs,
          result.active,
          iteration == 1
            ? "add a displacement or sliding boundary, or bring it into "
              "contact (zero gap)"
            : "at active-set iteration " + std::to_string(iteration) +
                " its load pulls it off its contact pairs");

        system.solve(result.active, excesses, result.lambda);
        had_inexact_solve = had_inexact_solve || !system.last_solve_exact();

        // The active-set test of step-41, and the NCP residual
        // |min(lambda_p, g_p - (A x)_p)| scaled by max lambda and max |u|.
        double lambda_scale = 0;
        for (const double l : result.lambda)
          lambda_scale = std::max(lambda_scale, std::abs(l));
        const double u_scale = std::max(system.displacement_scale(), 1e-300);
        if (lambda_scale == 0)
          lambda_scale = 1;
        const double      force_scale = force_scale_of_load + lambda_scale;
        std::vector<bool> next(n_pairs, false);
        unsigned int      n_entered = 0, n_left = 0, n_active = 0;
        // The first step from bodies held at points enters only their
        // deepest penetrations (first_step_thresholds()).
        const std::vector<double> entry =
          iteration == 1 && guess.empty()
            ? first_step_thresholds(pairs, excesses, result.active)
            : std::vector<double>(n_pairs, 0.);
        result.complementarity = 0;
        result.max_penetration = -std::numeric_limits<double>::max();
        for (unsigned int p = 0; p < n_pairs; ++p)
          {
            const double excess    = excesses[p];
            result.max_penetration = std::max(result.max_penetration, excess);
            result.complementarity =
              std::max(result.complementarity,
                       std::abs(std::min(result.lambda[p] / lambda_scale,
                                         -excess / u_scale)));
            // An active pair stays while lambda_p >= 0 up to round-off: an
            // unloaded contact (lambda = 0, zero load) is a solution, and
            // the strict test would release a body that only contact holds.
            next[p] =
              pairs[p].eliminated != numbers::invalid_dof_index &&
              (result.lambda[p] + c * (excess - entry[p]) > 0 ||
               (result.active[p] && result.lambda[p] >= -1e-12 * force_scale));
            n_active += next[p];
            n_entered += next[p] && !result.active[p];
            n_left += !next[p] && result.active[p];
          }
        // Safeguard after a cycle: of the pairs the test releases, release
        // only the one with the most negative multiplier.
        const auto release_one = [&]() {
          unsigned int release = numbers::invalid_unsigned_int;
          for (unsigned int p = 0; p < n_pairs; ++p)
            if (result.active[p] && !next[p] &&
                (release == numbers::invalid_unsigned_int ||
                 result.lambda[p] < result.lambda[release]))
              release = p;
          for (unsigned int p = 0; p < n_pairs; ++p)
            if (result.active[p] && !next[p] && p != release)
              {
                next[p] = true;
                ++n_active;
                --n_left;
              }
        };
        if (result.safeguard_from > 0)
          release_one();
        result.n_iterations = iteration;
        log << "   active set iteration " << std::setw(2) << iteration << ": "
            << std::setw(5) << n_active << " active pairs (+" << n_entered
            << " -" << n_left << "), complementarity residual "
            << std::scientific << std::setprecision(2) << result.complementarity
            << std::defaultfloat << Progress::stamp(log) << std::endl;

        // An inexact solve (the iterative path while the set changes) that
        // repeats its set is solved again to the final tolerance, from
        // where it stopped, before the set is accepted; so is the last set
        // of a loop that stops unconverged, so that what it reports is its
        // set's exact solution.
        if ((next == result.active || !failure.empty()) &&
            !system.last_solve_exact())
          {
            system.set_accuracy(0);
            continue;
          }
        // Whatever follows the loop (the error estimate's solves) asks for
        // its own accuracy.
        system.set_accuracy(0);
        if (!failure.empty())
          {
            result.converged = false;
            result.failure   = failure;
            return result;
          }
        if (next == result.active && result.complementarity <= tolerance)
          return result;
        if (next == result.active)
          failure = "the active set settled but the complementarity residual "
                    "stays above Contact/Tolerance";
        if (failure.empty() && seen.count(next) && inexact && had_inexact_solve)
          {
            // A set returns while the solves are inexact: the decisions
            // of pairs near zero may have been the Krylov solver's error.
            // From here on every solve is exact, and this set is solved
            // again.
            inexact = false;
            seen.clear();
            log << "   active set cycle at iteration " << iteration
                << " under inexact solves: exact solves from now on"
                << std::endl;
            continue;
          }
        if (failure.empty() && seen.count(next) && safeguard &&
            result.safeguard_from == 0)
          {
            // Switch the safeguard on and forget the history: from here on
            // the set changes by one release at a time.
            result.safeguard_from = iteration;
            log << "   active set cycle at iteration " << iteration
                << ": releasing at most one pair per iteration from now on"
                << std::endl;
            seen.clear();
            release_one();
          }
        if (failure.empty() && seen.count(next))
          failure =
            "the active set cycles (iteration " + std::to_string(iteration) +
            " returns to an earlier set); make the finer side the slave, "
            "or refine the coarse side of the interface";
        if (failure.empty() && iteration >= max_iterations)
          failure = "no convergence in " + std::to_string(max_iterations) +
                    " active-set iterations; raise 'Maximum active set "
                    "iterations' or refine the contact zone";
        if (!failure.empty())
          {
            if (!system.last_solve_exact())
              {
                // One more solve of this set to the final tolerance.
                system.set_accuracy(0);
                continue;
              }
            result.converged = false;
            result.failure   = failure;
            return result;
          }
        // While the set changes, the next solve needs only the accuracy
        // that decides it: a hundredth of this complementarity residual
        // (Eisenstat and Walker's forcing term for inexact Newton), at most
        // 1e-2 and no less than the loop's tolerance. Measured on the 3D
        // knee at 2.3e5 dofs (CG iterations of the loop, its time, its
        // active-set iterations): a cap of 1e-4 547, 27.5 s, 10; 1e-3 426,
        // 23.3 s, 11; 1e-2 327, 16.9 s, 12; 1e-1 315, 16.3 s, 12.
        if (inexact)
          system.set_accuracy(
            std::clamp(1e-2 * result.complementarity, tolerance, 1e-2));
        seen.insert(result.active);
        result.active = next;
      }
  }
} // namespace knee_contact
