#include <knee_contact/base/interruption.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/row_multipliers.h>
#include <knee_contact/solver/sparse_cholesky.h>
#include <knee_contact/solver/springs.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>
#include <deal.II/lac/sparsity_tools.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <Epetra_CrsMatrix.h>
#include <Epetra_Import.h>
#include <Epetra_Map.h>
#include <ml_MultiLevelPreconditioner.h>
#include <mpi.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <sstream>

namespace knee_contact
{
  namespace iterative
  {
    /** The resident memory of the process [MB]. */
    double
    resident_MB()
    {
      Utilities::System::MemoryStats stats;
      Utilities::System::get_memory_stats(stats);
      return stats.VmRSS / 1024.;
    }


    /**
     * The condensed operator of one active set, T^T C T on the free dofs
     * and C's diagonal on the constrained ones (whose right hand side is
     * zero), applied with the stiffness matrix itself: no copy per set.
     * With bound couplings T^T (I - B (M + E B)^-1 E) C T (RowMultipliers).
     */
    class CondensedOperator
    {
    public:
      CondensedOperator(const SparseMatrix<double>      &matrix,
                        const AffineConstraints<double> &constraints,
                        const std::vector<SpringTerm>   &springs,
                        const RowMultipliers            &coupling)
        : matrix(matrix)
        , constraints(constraints)
        , springs(springs)
        , coupling(coupling)
        , spread(matrix.m())
      {}

      void
      vmult(Vector<double> &dst, const Vector<double> &src) const
      {
        spread = src;
        sparse_cholesky::distribute_homogeneous(constraints, spread);
        matrix.vmult(dst, spread);
        for (const auto &spring : springs)
          {
            const double force = spring.stiffness * spring.dot(spread);
            for (const auto &[i, a] : spring.w)
              dst(i) += force * a;
          }
        coupling.project(dst);
        sparse_cholesky::condense_homogeneous(constraints, dst);
        for (const auto &line : constraints.get_lines())
          dst(line.index) = matrix.diag_element(line.index) * src(line.index);
      }

    private:
      const SparseMatrix<double>      &matrix;
      const AffineConstraints<double> &constraints;
      const std::vector<SpringTerm>   &springs;
      const RowMultipliers            &coupling;
      mutable Vector<double>           spread;
    };

    /**
     * The same operator over several ranks, on the distributed stiffness
     * matrix (this rank's rows of C, made once per mesh): x = T y sets
     * each owned constrained dof from its masters (read as ghosts), Trilinos
     * multiplies, and T^T r adds each owned constrained row's result to its
     * masters (written as ghosts, summed by compress). Every rank holds the
     * constraints (the replicated stage); only the vectors' owned parts and
     * the masters' ghosts move. Measured on the 3D knee at 2.3e5 dofs: a
     * whole-vector gather with deal.II's row loops took 82 ms a product,
     * forming each set's rows of T^T C T 0.5 s a set.
     */
    class DistributedCondensedOperator
    {
    public:
      DistributedCondensedOperator(const TrilinosWrappers::SparseMatrix &matrix,
                                   const AffineConstraints<double> &constraints,
                                   const IndexSet                  &owned,
                                   const std::vector<SpringTerm>   &springs,
                                   const RowMultipliers            &coupling)
        : matrix(matrix)
        , springs(springs)
        , coupling(coupling)
        , owned(owned)
      {
        const MPI_Comm comm = matrix.get_mpi_communicator();
        IndexSet       masters(owned.size());
        for (const auto &line : constraints.get_lines())
          if (owned.is_element(line.index))
            {
              lines.push_back(line);
              for (const auto &entry : line.entries)
                masters.add_index(entry.first);
            }
        masters.compress();
        IndexSet relevant = owned;
        relevant.add_indices(masters);
        spread.reinit(owned, comm);
        ghosted.reinit(owned, relevant, comm);
        to_masters.reinit(owned, relevant, comm, true);
        product.reinit(owned, comm);
        for (const auto &line : lines)
          diagonal.push_back(matrix.diag_element(line.index));

        // Every index the products touch, as Epetra's local index into the
        // vectors' arrays, found once per operator instead of by Epetra's
        // global-to-local lookup (a search on a METIS partition's
        // scattered rows) per entry and product.
        const auto local_in = [](const TrilinosWrappers::MPI::Vector &v,
                                 const types::global_dof_index        i) {
          const int lid =
            v.trilinos_vector().Map().LID(TrilinosWrappers::types::int_type(i));
          AssertThrow(lid >= 0, ExcInternalError());
          return lid;
        };
        for (const auto &line : lines)
          {
            line_local.push_back(local_in(spread, line.index));
            std::vector<Entry> entries;
            for (const auto &[master, weight] : line.entries)
              entries.push_back(
                {local_in(ghosted, master),
                 owned.is_element(master) ? local_in(spread, master) : -1,
                 master,
                 weight});
            line_entries.push_back(std::move(entries));
          }
        // Each spring's owned entries (local index, coefficient).
        for (const auto &spring : springs)
          {
            std::vector<std::pair<int, double>> local;
            for (const auto &[i, a] : spring.w)
              if (owned.is_element(i))
                local.emplace_back(local_in(spread, i), a);
            owned_w.push_back(std::move(local));
          }
      }

      void
      vmult(TrilinosWrappers::MPI::Vector       &dst,
            const TrilinosWrappers::MPI::Vector &src) const
      {
        Assert(
          src.trilinos_vector().Map().SameAs(spread.trilinos_vector().Map()) &&
            dst.trilinos_vector().Map().SameAs(spread.trilinos_vector().Map()),
          ExcInternalError());
        ghosted = src;
        spread  = src;
        {
          const double *x = ghosted.trilinos_vector()[0];
          double       *y = spread.trilinos_vector()[0];
          for (unsigned int k = 0; k < lines.size(); ++k)
            {
              double value = 0;
              for (const Entry &entry : line_entries[k])
                value += entry.weight * x[entry.ghosted];
              y[line_local[k]] = value;
            }
        }
        matrix.vmult(product, spread);
        double *r = product.trilinos_vector()[0];
        if (!springs.empty())
          {
            // w . x over the ranks' owned entries, summed by one reduction
            // for all springs.
            const double       *x = spread.trilinos_vector()[0];
            std::vector<double> stretch(springs.size(), 0.);
            for (unsigned int k = 0; k < springs.size(); ++k)
              for (const auto &[i, a] : owned_w[k])
                stretch[k] += a * x[i];
            Utilities::MPI::sum(stretch,
                                matrix.get_mpi_communicator(),
                                stretch);
            for (unsigned int k = 0; k < springs.size(); ++k)
              for (const auto &[i, a] : owned_w[k])
                r[i] += springs[k].stiffness * stretch[k] * a;
          }
        if (coupling.coupled())
          {
            // E r over the owned entries, summed over the ranks; the
            // (replicated) small solve; -B z on the owned entries.
            const auto &map   = product.trilinos_vector().Map();
            const auto  local = [&](const types::global_dof_index i) {
              return map.LID(TrilinosWrappers::types::int_type(i));
            };
            const auto mine = [&](const types::global_dof_index i) {
              return owned.is_element(i);
            };
            const Vector<double> part =
              coupling.gather(mine, [&](const auto i) { return r[local(i)]; });
            std::vector<double> sum(part.begin(), part.end());
            Utilities::MPI::sum(sum, matrix.get_mpi_communicator(), sum);
            Vector<double> z(sum.begin(), sum.end());
            coupling.solve(z);
            coupling.scatter(z, [&](const auto i, const double v) {
              if (mine(i))
                r[local(i)] += v;
            });
          }
        // T^T r: a constrained row's result goes to its masters, to an
        // owned master in place, to another rank's through to_masters.
        to_masters = 0;
        for (unsigned int k = 0; k < lines.size(); ++k)
          for (const Entry &entry : line_entries[k])
            if (entry.owned < 0)
              to_masters(entry.global) += entry.weight * r[line_local[k]];
        to_masters.compress(VectorOperation::add);
        dst = product;
        dst += to_masters;
        double       *d = dst.trilinos_vector()[0];
        const double *s = src.trilinos_vector()[0];
        for (unsigned int k = 0; k < lines.size(); ++k)
          for (const Entry &entry : line_entries[k])
            if (entry.owned >= 0)
              d[entry.owned] += entry.weight * r[line_local[k]];
        for (unsigned int k = 0; k < lines.size(); ++k)
          d[line_local[k]] = diagonal[k] * s[line_local[k]];
      }

    private:
      /** A master of a constrained row: its local index in the ghosted
       * vector, in the owned vectors (-1: another rank's), its global index
       * and weight. */
      struct Entry
      {
        int                     ghosted;
        int                     owned;
        types::global_dof_index global;
        double                  weight;
      };

      const TrilinosWrappers::SparseMatrix            &matrix;
      const std::vector<SpringTerm>                   &springs;
      const RowMultipliers                            &coupling;
      const IndexSet                                  &owned;
      std::vector<std::vector<std::pair<int, double>>> owned_w;
      /** The constrained dofs of this rank with their masters. */
      std::vector<AffineConstraints<double>::ConstraintLine> lines;
      std::vector<int>                                       line_local;
      std::vector<std::vector<Entry>>                        line_entries;
      std::vector<double>                                    diagonal;
      mutable TrilinosWrappers::MPI::Vector spread, ghosted, to_masters,
        product;
    };
  } // namespace iterative



  namespace
  {
    /**
     * What a new hierarchy costs, in CG iterations: the rules of solve()
     * rebuild a hierarchy when the iterations it costs beyond its own rate
     * exceed this (and give a kept one this many iterations more in its
     * budget). A count, not the measured set-up time over the measured time
     * of an iteration as before: the 3D knee's ratio measured 5.4 to 12.4
     * (2.3e5 and 1e6 dofs, one to four ranks, 2026-12-07) and varied with
     * the machine's load from run to run, so that the same scene took
     * different hierarchies and iterations (at 1e6 dofs two ranks took
     * three hierarchies and 260 CG iterations, 357 with two on 12-06). With
     * a count every run of a scene on N ranks takes the same hierarchies,
     * and every rank decides alike without a broadcast.
     */
    constexpr double setup_in_iterations = 10;

    /**
     * Trilinos ML ends the process by exit(1) when an allocation in its
     * hierarchy's set-up fails (its pr_error: "Not enough space to get a
     * matrix row", seen under an address-space limit in
     * hardening/memory_limit, where a run must end in the program's one
     * out-of-memory line): while a guard lives, an exit handler says so in
     * that line and leaves as main()'s out_of_memory() does (its temporary
     * files removed, exit code 1, ExitCode::input_error). Not a library's
     * job: ML offers no hook for it.
     */
    class MLExitGuard
    {
    public:
      MLExitGuard()
      {
        static const bool registered = std::atexit(&said_on_exit) == 0;
        (void)registered;
        active = true;
      }
      ~MLExitGuard()
      {
        active = false;
      }

    private:
      static inline std::atomic<bool> active{false};

      static void
      said_on_exit()
      {
        if (!active)
          return;
        std::cerr << "knee_contact: error: out of memory: Trilinos ML ended "
                     "the run while it built the AMG hierarchy (an allocation "
                     "failed)"
                  << std::endl;
        interruption::remove_registered();
        std::_Exit(1);
      }
    };
  } // namespace



  class IterativeContactSystem::Implementation
  {
  public:
    Implementation(const SparsityPattern                   *pattern,
                   const TrilinosWrappers::SparsityPattern *distributed_pattern,
                   const SparseMatrix<double>              *matrix,
                   const RowAssembly                       *assemble_rows,
                   const AffineConstraints<double>         &base,
                   const std::vector<ContactRow>           &pairs,
                   const RigidModeCheck                    &rigid_modes,
                   const KrylovSettings                    &settings)
      : matrix(matrix)
      , pattern(pattern)
      , distributed_pattern(distributed_pattern)
      , n(pattern != nullptr ? pattern->n_rows()
                             : distributed_pattern->n_rows())
      , base(base)
      , pairs(pairs)
      , components(rigid_modes.components())
      , settings(settings)
      , x(n)
    {
      AssertThrow((pattern == nullptr) != (distributed_pattern == nullptr) &&
                    (matrix == nullptr) != (assemble_rows == nullptr) &&
                    (distributed_pattern == nullptr || matrix == nullptr),
                  ExcInternalError());
      // This rank's rows: whole vertices (the aggregation's blocks), a
      // METIS partition of the vertex graph made on rank 0 (a contiguous
      // block of gmsh's cell-by-cell numbering scattered over the bodies:
      // the 3D knee at 2.3e5 dofs took twice the CG iterations of one
      // rank). Every rank holds the rows (the replicated first stage of the
      // parallel run, doc/parallel.md); C (its rows assembled here:
      // rows_of_c()), the condensed matrix, the hierarchy and the Krylov
      // vectors are distributed.
      const unsigned int ranks = parallel::n_ranks(), rank = parallel::rank();
      Timer              clock;
      owned.set_size(n);
      if (distributed_pattern != nullptr)
        // A distributed mesh: the DoF handler's rows (whole vertices, those
        // of the cells the rank owns).
        owned = distributed_pattern->locally_owned_range_indices();
      else if (ranks == 1 || n % components != 0)
        owned.add_range(n * rank / ranks,
                        rank + 1 == ranks ? n : n * (rank + 1) / ranks);
      else
        {
          const types::global_dof_index n_blocks = n / components;
          std::vector<unsigned int>     rank_of_block(n_blocks, 0);
          if (rank == 0)
            {
              DynamicSparsityPattern graph(n_blocks, n_blocks);
              for (types::global_dof_index i = 0; i < n; i += components)
                for (auto entry = pattern->begin(i); entry != pattern->end(i);
                     ++entry)
                  graph.add(i / components, entry->column() / components);
              SparsityPattern blocks;
              blocks.copy_from(graph);
              SparsityTools::partition(blocks, ranks, rank_of_block);
            }
          rank_of_block = Utilities::MPI::broadcast(parallel::communicator(),
                                                    rank_of_block,
                                                    0);
          for (types::global_dof_index b = 0; b < n_blocks; ++b)
            if (rank_of_block[b] == rank)
              owned.add_range(b * components, (b + 1) * components);
        }
      owned.compress();
      partition_time = clock.wall_time();
      // ML reads the near null space as one column-major array of this
      // rank's rows (kept for each new hierarchy; whole it took 48 MB a
      // rank at 1e6 dofs).
      null_space = rigid_modes.rigid_motions(owned);
      n_modes    = rigid_modes.n_rigid_motions();
      if (matrix == nullptr)
        assemble_rows_of_c(*assemble_rows);
    }

    /** C whole on one rank; none on several (rows_of_c()). */
    const SparseMatrix<double> *matrix;
    /** Every set's condensed pattern: whole (a whole mesh), or this rank's
     * rows of it (a distributed mesh, whose owned cells give C's rows). */
    const SparsityPattern                   *pattern;
    const TrilinosWrappers::SparsityPattern *distributed_pattern;
    const types::global_dof_index            n;
    const AffineConstraints<double>         &base;
    const std::vector<ContactRow>           &pairs;
    const unsigned int                       components;
    const KrylovSettings                     settings;
    const Vector<double>                    *rhs = nullptr;
    std::vector<double>                      null_space;
    unsigned int                             n_modes = 0;

    /** The springs of the following solves (set_springs()), as the loop
     * gave them and on the dofs. */
    std::vector<ContactSystem::Spring> given_springs;
    std::vector<SpringTerm>            springs;
    /** Those of the current solve left to the operator (the others are
     * tied: springs::tie_stiff()). */
    std::vector<SpringTerm> operator_springs;
    /** The bound couplings of the following solves, and the current
     * solve's multipliers with them (its operator's projection). */
    std::vector<ContactSystem::BoundCoupling> couplings;
    std::unique_ptr<RowMultipliers>           coupling;
    /** The rows of this rank (all of them on one). */
    IndexSet                       owned;
    AffineConstraints<double>      constraints;
    TrilinosWrappers::SparseMatrix amg_matrix;
    /** The pattern of this rank's rows (every set's; owned_pattern()). */
    TrilinosWrappers::SparsityPattern trilinos_pattern;
    /** Several ranks: this rank's rows of C. */
    TrilinosWrappers::SparseMatrix distributed_matrix;
    /** Several ranks: the dofs a line can hold (the base's lines, the dofs
     * of the contact rows). */
    std::vector<bool> of_line;
    /** Several ranks: C's rows of the lines with a master this rank owns
     * and a row it does not (condense() reads them), fetched from their
     * owners when a set first needs them and kept: this rank's part of
     * the surface. Until 2026-12-02 every rank held C's rows of every dof a
     * line can hold, whole (181 MB a rank at 1e6 DoFs). */
    std::map<types::global_dof_index,
             std::vector<std::pair<types::global_dof_index, double>>>
      held_rows;
    /** Several ranks: C's diagonal on every dof a line can hold, on every
     * rank (the ties' decisions read it, replicated: springs::tie_stiff()),
     * by dof. */
    struct DofValue
    {
      types::global_dof_index dof;
      double                  value;
    };
    std::vector<DofValue> line_diagonal;
    /** Several ranks: this rank's rows with a column a line can hold, and
     * those columns (condense() finds the rows a set changes from them),
     * row by row: the columns of rows[r] are columns[start[r]] up to
     * columns[start[r + 1]] (pairs of row and column took twice the
     * memory: 39 MB of a rank's peak at 1e6 DoFs on four ranks). */
    struct LineColumns
    {
      std::vector<types::global_dof_index> rows;
      std::vector<std::size_t>             start;
      std::vector<types::global_dof_index> columns;
    } line_columns;
    TrilinosWrappers::PreconditionAMG amg;
    bool                              has_amg = false;
    /** The set the hierarchy was built for, and the dofs its tied
     * springs eliminated. */
    std::vector<bool>                    amg_active;
    std::vector<types::global_dof_index> amg_tied;
    /** Whether amg_matrix holds a condensed matrix, and its rows that
     * depend on its set (condense()). */
    bool amg_filled = false;
    /** This rank's part of the near null space (ML reads it again when it
     * recomputes a hierarchy). */
    std::vector<double>                  modes;
    std::vector<types::global_dof_index> amg_set_rows;
    Vector<double>                       x;
    double                               accuracy = 0;
    /** set_accuracy()'s accuracy is of the start's residual. */
    bool accuracy_of_start = false;
    bool exact             = false;
    /** Springs the last solve held as rows. */
    std::size_t n_tied_last = 0;
    /** CG iterations per decade of the residual: after the last set-up,
     * and of the last solve. */
    double rate_at_build = 0, last_decades = 1;

    // Figures.
    double       resident_at_start = 0, measured_MB = 0;
    unsigned int reference_iterations = 0;
    double       condensation         = 0;
    /** Several ranks: the partition's and the rows' assembly's times. */
    double       partition_time = 0, rows_assembly = 0;
    unsigned int last_iterations = 0;
    /** The loop's totals for statistics() (the reference solve keeps them
     * as they were). */
    struct Totals
    {
      double       setup = 0, krylov = 0;
      unsigned int n_setups = 0, n_recomputed = 0, n_solves = 0,
                   n_iterations = 0, max_iterations = 0, n_over_budget = 0,
                   n_tied = 0, n_coupled = 0;
    } totals;

    /** A hierarchy for the current set: ML's recomputation on the
     * current one's aggregates, or with @p anew (or none yet) a new one. */
    void
    build_amg(const bool anew = false);

    /** Several ranks: this rank's rows of C into distributed_matrix,
     * assembled by @p assemble (C whole is never made; on a distributed
     * mesh @p assemble gives the cells this rank owns), then of_line,
     * line_diagonal and line_columns. */
    void
    assemble_rows_of_c(const RowAssembly &assemble);

    /** Several ranks: into held_rows the rows of the current lines with a
     * master this rank owns that it holds not yet. Collective. */
    void
    fetch_rows();

    /** C's diagonal entry of a dof a line can hold (any dof on one rank). */
    double
    diagonal(const types::global_dof_index i) const;

    /** Calls @p f(column, value) for each entry of C's row @p row (any row
     * on one rank; on several an owned row or a held one). */
    template <typename Function>
    void
    for_each_in_row(const types::global_dof_index row, const Function &f) const;

    /** y = C x (whole on every rank). */
    void
    product(Vector<double> &y, const Vector<double> &x) const;

    /** The stiffness matrix's pattern, this rank's rows, in Trilinos
     * (made on the first call): it holds every set's condensed rows. */
    const TrilinosWrappers::SparsityPattern &
    owned_pattern();

    /** amg_matrix: the condensed matrix of the current set, this rank's
     * rows. */
    void
    condense();

    /** CG (GMRES with couplings) from @p y on the condensed system with
     * right hand side @p b (replicated). */
    void
    krylov(Vector<double>       &y,
           const Vector<double> &b,
           SolverControl        &control,
           double               &target,
           const double          b_norm,
           const double          target_relative,
           const double          budget_rate,
           const double          budget_extra);
  };



  void
  IterativeContactSystem::Implementation::build_amg(const bool anew)
  {
    const MLExitGuard guard;
    Timer             clock;
    // With springs another set's hierarchy is recomputed on its aggregates
    // (the caller makes a frictionless set's anew: solve()) (ML's
    // ReComputePreconditioner: the same aggregates and null space, the new
    // matrix's Galerkin products and smoothers; the matrix is refilled in
    // place, as ML asks). Measured on the 3D knee's stance with friction at
    // 1.25e5 dofs (2026-11-28): 0.2 s against 0.4 s for ML's part of a
    // set-up, and fewer Krylov iterations in all than with new aggregates
    // at every set-up: the first case's contact solve 16.7 s against 32.5,
    // the further cases' 36.1 against 80.9 (new aggregates every 4th
    // set-up: 23.3 and 52.4). A hierarchy over its budget is made anew.
    if (has_amg && !anew)
      {
        condense();
        dynamic_cast<ML_Epetra::MultiLevelPreconditioner &>(
          amg.trilinos_operator())
          .ReComputePreconditioner();
        ++totals.n_setups;
        ++totals.n_recomputed;
        totals.setup += clock.wall_time();
        return;
      }
    // The old hierarchy goes first: kept while the new one was made, a
    // rebuild (and the benchmark's reference solve) held two hierarchies,
    // about 10 bytes per matrix entry more than the estimate.
    amg.clear();
    // The heap's free pages go back first (the largest of four ranks'
    // peaks at 1e6 dofs 1 253-1 271 -> 1 201-1 215 MB, doc/parallel.md).
    memory::return_free_heap();
    condense();
    // This rank's part of the null space, zero on the constrained dofs:
    // their rows are decoupled.
    const types::global_dof_index n_local = owned.n_elements();
    modes                                 = null_space;
    for (const auto &line : constraints.get_lines())
      if (owned.is_element(line.index))
        for (unsigned int k = 0; k < n_modes; ++k)
          modes[k * n_local + owned.index_within_set(line.index)] = 0;

    // Aggregation AMG for elasticity (one V-cycle, Chebyshev smoothing of
    // degree 2, coarsest level direct), with the rigid motions as the near
    // null space: deal.II 9.4's AdditionalData carries only translations,
    // so ML gets its own list. Plain aggregation (no prolongator
    // smoothing): measured on the 3D knee's tetrahedra (34 059 and 232 989
    // dofs), smoothed aggregation saved 5 % of the CG iterations but took
    // 2.3 times the hierarchy's memory (770 against 330 MB at 2.3e5 dofs)
    // and 20 % more time; Gauss-Seidel smoothing 25 % fewer iterations at
    // twice the time. In 2D (prm/hertz.prm, 7e3 to 4.3e5 dofs, measured
    // 2026-11-27) smoothed aggregation kept a fresh solve's CG iterations
    // nearly bounded (21, 26, 27, 34 against 33, 55, 59, 101), but its
    // hierarchy served later active sets worse (at most 255 against 128
    // iterations per solve) and the contact solve took 23 against 16.9 s at
    // 4.3e5 dofs, with twice the hierarchy's memory.
    Teuchos::ParameterList list;
    ML_Epetra::SetDefaults("SA", list);
    list.set("ML output", 0);
    list.set("aggregation: damping factor", 0.);
    list.set("aggregation: type", "Uncoupled");
    list.set("aggregation: threshold", 1e-4);
    list.set("smoother: type", "Chebyshev");
    list.set("smoother: sweeps", 2);
    list.set("coarse: type", "Amesos-KLU");
    list.set("coarse: max size", 2000);
    list.set("PDE equations", int(components));
    list.set("null space: type", "pre-computed");
    list.set("null space: dimension", int(n_modes));
    // (A rank without rows passes an array all the same: a null pointer
    // makes ML ignore the dimension, and warn.)
    if (modes.empty())
      modes.resize(1);
    list.set("null space: vectors", modes.data());
    amg.initialize(amg_matrix, list);
    has_amg = true;
    ++totals.n_setups;
    totals.setup += clock.wall_time();
  }



  void
  IterativeContactSystem::Implementation::condense()
  {
    // This rank's rows of T^T C T (C's diagonal on the constrained lines,
    // as CondensedOperator), which deal.II does not offer in this form
    // (AffineConstraints::condense takes the whole matrix: on the 3D knee
    // at 2.3e5 dofs its copy and condensation on every rank made two ranks
    // slower than one; on one rank its copy, condensation and Trilinos's
    // copy took 0.5 of a 0.9 s set-up at 1.25e5 dofs, 35 set-ups in a
    // frictional run). Row i receives C's row i with each constrained
    // column spread over its masters, and every constrained row l with
    // master i, weighted (the constraints are closed: masters are free).
    // Summed on the pattern, which holds every set's condensed system
    // (ActiveSetSolver::make_sparsity_pattern).
    //
    // Only the rows a set changes are made again: those of its lines that
    // are not the base's (the contact rows and the tied springs), the
    // rows with such a line's dof as a column (C is symmetric: the line's
    // row's columns), its masters, and the masters of constrained rows
    // among these. The last set's rows are made again too (to drop what
    // it added); every other row is the base's condensation, the same for
    // every set.
    if (matrix == nullptr)
      fetch_rows();
    std::vector<bool> of_set(n, false), set_line(n, false);
    bool              indexed = true;
    for (const auto &line : constraints.get_lines())
      {
        const auto *in_base = base.get_constraint_entries(line.index);
        if (in_base != nullptr && *in_base == line.entries)
          continue;
        of_set[line.index] = true;
        for (const auto &[master, weight] : line.entries)
          of_set[master] = true;
        if (matrix != nullptr)
          for_each_in_row(line.index,
                          [&](const types::global_dof_index j, const double) {
                            of_set[j] = true;
                          });
        else
          {
            set_line[line.index] = true;
            indexed &= of_line[line.index];
          }
      }
    if (matrix == nullptr)
      {
        // Several ranks: a line's row is not here, but C is symmetric: the
        // rows with the set's lines as columns are those it marks, and of
        // them the rows this one makes read only its own and the held ones
        // (a line's row with such a column matters where its masters are
        // this rank's: it is held). The own ones from line_columns (a line
        // of a dof no line was expected on: every row).
        const auto mark = [&](const types::global_dof_index row) {
          for_each_in_row(row,
                          [&](const types::global_dof_index j, const double) {
                            if (set_line[j])
                              of_set[row] = true;
                          });
        };
        if (indexed)
          for (std::size_t r = 0; r < line_columns.rows.size(); ++r)
            for (std::size_t k = line_columns.start[r];
                 k < line_columns.start[r + 1] && !of_set[line_columns.rows[r]];
                 ++k)
              of_set[line_columns.rows[r]] = set_line[line_columns.columns[k]];
        else
          for (const auto row : owned)
            mark(row);
        for (const auto &[row, entries] : held_rows)
          mark(row);
      }
    for (const auto &line : constraints.get_lines())
      if (of_set[line.index])
        for (const auto &[master, weight] : line.entries)
          of_set[master] = true;

    // This rank's rows to make: all on the first call, else this set's and
    // the last set's.
    std::vector<bool> remake(n, false);
    for (const auto i : amg_set_rows)
      remake[i] = true;
    std::vector<types::global_dof_index> rows;
    amg_set_rows.clear();
    for (const auto row : owned)
      {
        remake[row] = !amg_filled || remake[row] || of_set[row];
        if (remake[row])
          rows.push_back(row);
        if (of_set[row])
          amg_set_rows.push_back(row);
      }

    // Each row is summed once in a dense scratch row and written into
    // Trilinos whole, on the pattern's columns (a deal.II matrix on the
    // whole pattern for the sums, copied row by row, held 8 bytes per
    // entry of C on every rank: 112 MB of the 3D knee's iterative path at
    // 2.3e5 dofs).
    std::vector<double>                  row_of(n, 0.);
    std::vector<bool>                    in_row(n, false);
    std::vector<types::global_dof_index> columns;
    const auto add = [&](const types::global_dof_index j, const double v) {
      if (!in_row[j])
        columns.push_back(j);
      in_row[j] = true;
      row_of[j] += v;
    };
    const auto clear = [&]() {
      for (const auto j : columns)
        {
          row_of[j] = 0;
          in_row[j] = false;
        }
      columns.clear();
    };
    // Adds C's row @p from, its constrained columns spread over their
    // masters, to the scratch row.
    const auto add_spread = [&](const types::global_dof_index from) {
      for_each_in_row(from,
                      [&](const types::global_dof_index j, const double v) {
                        if (const auto *masters =
                              constraints.get_constraint_entries(j))
                          for (const auto &[master, w] : *masters)
                            add(master, w * v);
                        else
                          add(j, v);
                      });
    };
    // The lines each row to make is a master of (with the weight), and
    // those lines' spread rows, made once (a contact row has tens of
    // masters: spreading it for each one took 0.5 s a set-up at 1.25e5
    // dofs).
    using Entries = std::vector<std::pair<types::global_dof_index, double>>;
    std::map<types::global_dof_index, Entries> lines_of, spread_lines;
    for (const auto &line : constraints.get_lines())
      for (const auto &[master, weight] : line.entries)
        if (remake[master])
          {
            lines_of[master].emplace_back(line.index, weight);
            auto [spread, is_new] = spread_lines.try_emplace(line.index);
            if (is_new)
              {
                add_spread(line.index);
                for (const auto j : columns)
                  spread->second.emplace_back(j, row_of[j]);
                clear();
              }
          }

    if (amg_matrix.m() != n)
      amg_matrix.reinit(owned_pattern());
    const Epetra_CrsGraph &graph = owned_pattern().trilinos_sparsity_pattern();
    std::vector<types::global_dof_index> row_columns;
    std::vector<double>                  values;
    for (const auto row : rows)
      {
        const bool constrained = constraints.is_constrained(row);
        if (!constrained)
          {
            add_spread(row);
            const auto found = lines_of.find(row);
            if (found != lines_of.end())
              for (const auto &[line, weight] : found->second)
                for (const auto &[j, v] : spread_lines[line])
                  add(j, weight * v);
          }
        row_columns.clear();
        values.clear();
        int  length  = 0;
        int *indices = nullptr;
        graph.ExtractMyRowView(
          graph.LRID(TrilinosWrappers::types::int_type(row)), length, indices);
        for (int k = 0; k < length; ++k)
          {
            const types::global_dof_index j = graph.ColMap().GID(indices[k]);
            row_columns.push_back(j);
            values.push_back(constrained ? (j == row ? diagonal(row) : 0.)
                                         : row_of[j]);
          }
        amg_matrix.set(row,
                       row_columns.size(),
                       row_columns.data(),
                       values.data());
        clear();
      }
    amg_matrix.compress(VectorOperation::insert);
    amg_filled = true;
  }



  const TrilinosWrappers::SparsityPattern &
  IterativeContactSystem::Implementation::owned_pattern()
  {
    if (distributed_pattern != nullptr)
      return *distributed_pattern;
    if (trilinos_pattern.n_rows() != n)
      {
        trilinos_pattern.reinit(owned, owned, parallel::communicator());
        // A row at a time (an entry at a time took 1 s at 2.3e5 dofs).
        std::vector<types::global_dof_index> columns;
        for (const auto row : owned)
          {
            columns.clear();
            for (auto entry = pattern->begin(row); entry != pattern->end(row);
                 ++entry)
              columns.push_back(entry->column());
            trilinos_pattern.add_entries(row, columns.begin(), columns.end());
          }
        trilinos_pattern.compress();
      }
    return trilinos_pattern;
  }



  void
  IterativeContactSystem::Implementation::assemble_rows_of_c(
    const RowAssembly &assemble)
  {
    Timer clock;
    if (distributed_pattern != nullptr)
      {
        // Each rank adds the cells it owns (a row another rank owns is sent
        // to it by compress(): the cells at a partition's border are made
        // once).
        distributed_matrix.reinit(*distributed_pattern);
        assemble([](const types::global_dof_index) { return true; },
                 [&](const std::vector<types::global_dof_index> &dofs,
                     const FullMatrix<double>                   &cell_matrix) {
                   distributed_matrix.add(dofs, cell_matrix);
                 });
      }
    else
      {
        // Each rank sums the cells around its rows into them (the cells at
        // a partition's border on both sides): no rows are sent between
        // ranks.
        distributed_matrix.reinit(owned_pattern());
        std::vector<bool> is_owned(n, false);
        for (const auto i : owned)
          is_owned[i] = true;
        std::vector<double> values;
        assemble(
          [&](const types::global_dof_index i) { return bool(is_owned[i]); },
          [&](const std::vector<types::global_dof_index> &dofs,
              const FullMatrix<double>                   &cell_matrix) {
            values.resize(dofs.size());
            for (unsigned int a = 0; a < dofs.size(); ++a)
              if (is_owned[dofs[a]])
                {
                  for (unsigned int b = 0; b < dofs.size(); ++b)
                    values[b] = cell_matrix(a, b);
                  distributed_matrix.add(
                    dofs[a], dofs.size(), dofs.data(), values.data(), false);
                }
          });
      }
    distributed_matrix.compress(VectorOperation::add);

    // The dofs a line can hold: the base's lines and every dof of a
    // contact row (a row eliminates one of its own dofs; so does a tied
    // spring, whose dofs are its rows'). O(surface) of them.
    of_line.assign(n, false);
    for (const auto &line : base.get_lines())
      of_line[line.index] = true;
    for (const auto &row : pairs)
      {
        for (const auto &[j, a] : row.row)
          of_line[j] = true;
        for (const auto &[j, a] : row.reduced_row)
          of_line[j] = true;
      }
    // Their diagonal from their owners to every rank; this rank's rows
    // with such a column.
    std::vector<DofValue> mine;
    line_columns = {};
    line_columns.start.push_back(0);
    for (const auto row : owned)
      {
        if (of_line[row])
          mine.push_back({row, distributed_matrix.diag_element(row)});
        for_each_in_row(row,
                        [&](const types::global_dof_index j, const double) {
                          if (of_line[j])
                            line_columns.columns.push_back(j);
                        });
        if (line_columns.columns.size() > line_columns.start.back())
          {
            line_columns.rows.push_back(row);
            line_columns.start.push_back(line_columns.columns.size());
          }
      }
    line_columns.rows.shrink_to_fit();
    line_columns.start.shrink_to_fit();
    line_columns.columns.shrink_to_fit();
    line_diagonal =
      parallel::gather_on_every_rank(parallel::communicator(), mine);
    // (Rank order: each rank's rows are increasing, but on a METIS
    // partition the ranks' are not contiguous.)
    std::sort(line_diagonal.begin(),
              line_diagonal.end(),
              [](const DofValue &a, const DofValue &b) {
                return a.dof < b.dof;
              });
    rows_assembly = clock.wall_time();
  }



  void
  IterativeContactSystem::Implementation::fetch_rows()
  {
    // Why by hand: the rows a rank needs follow the set, so deal.II's
    // locally relevant sets (made once, from the mesh) do not hold them;
    // Epetra's Import moves them from their owners.
    using Index = TrilinosWrappers::types::int_type;
    std::vector<Index> missing;
    for (const auto &line : constraints.get_lines())
      if (!owned.is_element(line.index) && held_rows.count(line.index) == 0)
        for (const auto &[master, weight] : line.entries)
          if (owned.is_element(master))
            {
              missing.push_back(Index(line.index));
              break;
            }
    const MPI_Comm comm = parallel::communicator();
    if (Utilities::MPI::max(static_cast<unsigned long>(missing.size()), comm) ==
        0)
      return;
    const Epetra_CrsMatrix &source = distributed_matrix.trilinos_matrix();
    const Epetra_Map        target(Index(-1),
                                   int(missing.size()),
                            missing.empty() ? nullptr : missing.data(),
                                   0,
                                   source.Comm());
    const Epetra_Import     importer(target, source.RowMap());
    Epetra_CrsMatrix        fetched(Copy, target, 0);
    AssertThrow(fetched.Import(source, importer, Insert) == 0,
                ExcInternalError());
    for (const Index row : missing)
      {
        int     length  = 0;
        double *values  = nullptr;
        Index  *columns = nullptr;
        AssertThrow(
          fetched.ExtractGlobalRowView(row, length, values, columns) == 0,
          ExcInternalError());
        auto &held = held_rows[types::global_dof_index(row)];
        held.reserve(length);
        for (int k = 0; k < length; ++k)
          held.emplace_back(types::global_dof_index(columns[k]), values[k]);
      }
  }



  double
  IterativeContactSystem::Implementation::diagonal(
    const types::global_dof_index i) const
  {
    if (matrix != nullptr)
      return matrix->diag_element(i);
    const auto found =
      std::lower_bound(line_diagonal.begin(),
                       line_diagonal.end(),
                       i,
                       [](const DofValue &a, const types::global_dof_index j) {
                         return a.dof < j;
                       });
    AssertThrow(found != line_diagonal.end() && found->dof == i,
                ExcInternalError());
    return found->value;
  }



  template <typename Function>
  void
  IterativeContactSystem::Implementation::for_each_in_row(
    const types::global_dof_index row,
    const Function               &f) const
  {
    if (matrix != nullptr)
      {
        for (auto entry = matrix->begin(row); entry != matrix->end(row);
             ++entry)
          f(entry->column(), entry->value());
        return;
      }
    if (!owned.is_element(row))
      {
        for (const auto &[j, value] : held_rows.at(row))
          f(j, value);
        return;
      }
    // An owned row: Epetra's own view of it (deal.II's iterators over a
    // Trilinos matrix copy each row they visit).
    const Epetra_CrsMatrix &epetra = distributed_matrix.trilinos_matrix();
    const int               local =
      epetra.RowMap().LID(TrilinosWrappers::types::int_type(row));
    AssertThrow(local >= 0, ExcInternalError());
    int     length  = 0;
    double *values  = nullptr;
    int    *columns = nullptr;
    epetra.ExtractMyRowView(local, length, values, columns);
    for (int k = 0; k < length; ++k)
      f(types::global_dof_index(epetra.ColMap().GID(columns[k])), values[k]);
  }



  void
  IterativeContactSystem::Implementation::product(Vector<double>       &y,
                                                  const Vector<double> &x) const
  {
    if (matrix != nullptr)
      {
        matrix->vmult(y, x);
        return;
      }
    // This rank's rows, then every rank takes the whole product.
    const MPI_Comm                comm = parallel::communicator();
    TrilinosWrappers::MPI::Vector from(owned, comm), to(owned, comm);
    {
      // By local index (a global one is a search in the partition's map).
      Epetra_FEVector &entries = from.trilinos_vector();
      for (int k = 0; k < entries.Map().NumMyElements(); ++k)
        entries[0][k] = x(entries.Map().GID(k));
    }
    distributed_matrix.vmult(to, from);
    y = Vector<double>(to);
  }



  void
  IterativeContactSystem::Implementation::krylov(Vector<double>       &y,
                                                 const Vector<double> &b,
                                                 SolverControl        &control,
                                                 double               &target,
                                                 const double          b_norm,
                                                 const double target_relative,
                                                 const double budget_rate,
                                                 const double budget_extra)
  {
    // An inexact solve must still resolve what the new set changed: its
    // residual falls at least tenfold from the warm start's (an inexact
    // Newton step's forcing term of 0.1). Without this a start already
    // below the loose target took no iteration, the loop decided on the
    // old set's solution and added back the pairs it had just released
    // (measured: the Hertz sphere at 3.4e5 dofs alternated for 20
    // iterations). A hundredfold cost 23 % more CG iterations on the knee
    // at 2.3e5 dofs (438 against 355) and 8 % on that Hertz sphere (795
    // against 733, both converging in 22 active-set iterations).
    // (A target set by an earlier part of this solve stays.) With a
    // budget rate, at most 1.5 x rate x decades + extra iterations.
    const auto set_target = [&](const double start_residual) {
      if (target == 0)
        target = std::max(settings.tolerance * b_norm,
                          accuracy_of_start ? target_relative * start_residual
                                            : std::min(target_relative * b_norm,
                                                       1e-1 * start_residual));
      control.set_tolerance(target);
      if (budget_rate > 0 && start_residual > target)
        control.set_max_steps(std::min<double>(
          control.max_steps(),
          std::ceil(1.5 * budget_rate * std::log10(start_residual / target) +
                    budget_extra)));
    };
    if (matrix != nullptr)
      {
        iterative::CondensedOperator operation(*matrix,
                                               constraints,
                                               operator_springs,
                                               *coupling);
        Vector<double>               start_residual(b.size());
        operation.vmult(start_residual, y);
        start_residual.sadd(-1., 1., b);
        set_target(start_residual.l2_norm());
        if (coupling->coupled())
          {
            SolverGMRES<Vector<double>> gmres(
              control,
              SolverGMRES<Vector<double>>::AdditionalData(
                IterativeContactSystem::gmres_basis, true));
            gmres.solve(operation, y, b, amg);
          }
        else
          {
            SolverCG<Vector<double>> cg(control);
            cg.solve(operation, y, b, amg);
          }
        return;
      }

    // Several ranks: the matrix of this set is never formed.
    const iterative::DistributedCondensedOperator operation(
      distributed_matrix, constraints, owned, operator_springs, *coupling);
    const MPI_Comm                comm = parallel::communicator();
    TrilinosWrappers::MPI::Vector y_owned(owned, comm), b_owned(owned, comm),
      start_residual(owned, comm);
    for (const auto i : owned)
      {
        y_owned(i) = y(i);
        b_owned(i) = b(i);
      }
    y_owned.compress(VectorOperation::insert);
    b_owned.compress(VectorOperation::insert);
    operation.vmult(start_residual, y_owned);
    start_residual.sadd(-1., 1., b_owned);
    set_target(start_residual.l2_norm());
    if (coupling->coupled())
      {
        SolverGMRES<TrilinosWrappers::MPI::Vector> gmres(
          control,
          SolverGMRES<TrilinosWrappers::MPI::Vector>::AdditionalData(
            IterativeContactSystem::gmres_basis, true));
        gmres.solve(operation, y_owned, b_owned, amg);
      }
    else
      {
        SolverCG<TrilinosWrappers::MPI::Vector> cg(control);
        cg.solve(operation, y_owned, b_owned, amg);
      }
    // Every rank takes the whole solution (the rows and the results are
    // replicated).
    y = Vector<double>(y_owned);
  }



  IterativeContactSystem::IterativeContactSystem(
    const SparseMatrix<double>      &matrix,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs,
    const RigidModeCheck            &rigid_modes,
    const KrylovSettings            &settings)
    : IterativeContactSystem(&matrix.get_sparsity_pattern(),
                             nullptr,
                             &matrix,
                             nullptr,
                             base,
                             pairs,
                             rigid_modes,
                             settings)
  {}



  IterativeContactSystem::IterativeContactSystem(
    const SparsityPattern           &pattern,
    const RowAssembly               &assemble_rows,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs,
    const RigidModeCheck            &rigid_modes,
    const KrylovSettings            &settings)
    : IterativeContactSystem(&pattern,
                             nullptr,
                             nullptr,
                             &assemble_rows,
                             base,
                             pairs,
                             rigid_modes,
                             settings)
  {}



  IterativeContactSystem::IterativeContactSystem(
    const TrilinosWrappers::SparsityPattern &pattern,
    const RowAssembly                       &assemble_cells,
    const AffineConstraints<double>         &base,
    const std::vector<ContactRow>           &pairs,
    const RigidModeCheck                    &rigid_modes,
    const KrylovSettings                    &settings)
    : IterativeContactSystem(nullptr,
                             &pattern,
                             nullptr,
                             &assemble_cells,
                             base,
                             pairs,
                             rigid_modes,
                             settings)
  {}



  IterativeContactSystem::IterativeContactSystem(
    const SparsityPattern                   *pattern,
    const TrilinosWrappers::SparsityPattern *distributed_pattern,
    const SparseMatrix<double>              *matrix,
    const RowAssembly                       *assemble_rows,
    const AffineConstraints<double>         &base,
    const std::vector<ContactRow>           &pairs,
    const RigidModeCheck                    &rigid_modes,
    const KrylovSettings                    &settings)
  {
    parallel::ensure_initialised();
    // (Before the implementation: on several ranks it assembles its rows.)
    // The heap freed before is given back first, as the first hierarchy
    // does (build_amg()): else the path's measured memory was that less,
    // -68 MB on four ranks at 1e6 dofs against an estimate of 642.
    memory::return_free_heap();
    const double resident = iterative::resident_MB();
    implementation        = std::make_unique<Implementation>(pattern,
                                                      distributed_pattern,
                                                      matrix,
                                                      assemble_rows,
                                                      base,
                                                      pairs,
                                                      rigid_modes,
                                                      settings);
    implementation->resident_at_start = resident;
  }



  IterativeContactSystem::~IterativeContactSystem() = default;



  void
  IterativeContactSystem::set_rhs(const Vector<double> &rhs)
  {
    implementation->rhs = &rhs;
  }



  void
  IterativeContactSystem::set_accuracy(const double relative,
                                       const bool   of_start)
  {
    implementation->accuracy          = relative;
    implementation->accuracy_of_start = of_start && relative > 0;
  }



  void
  IterativeContactSystem::start_from(const Vector<double> &x)
  {
    AssertThrow(x.size() == implementation->n, ExcInternalError());
    implementation->x = x;
  }



  bool
  IterativeContactSystem::last_solve_exact() const
  {
    return implementation->exact;
  }



  bool
  IterativeContactSystem::springs_held_as_rows() const
  {
    return implementation->n_tied_last > 0;
  }



  void
  IterativeContactSystem::solve(const std::vector<bool> &active,
                                std::vector<double>     &excess,
                                std::vector<double>     &lambda)
  {
    Implementation &d = *implementation;
    Assert(d.rhs != nullptr, ExcMessage("set_rhs() was not called"));
    Timer clock;
    // The springs at least as stiff as C on their dofs are held as rows
    // (springs::tie_stiff()). Measured on the 3D knee with friction (34 059
    // dofs, two load cases): tying at 100 x C left springs of 1 to 100 x C,
    // and the second case's CG did not converge in 1 000 iterations; at
    // 1 x and 10 x the same springs are tied (their stiffnesses are far
    // apart: most below 0.02 x, a few above 30 x), both cases converge in
    // the Newton iterations of the sparse path (13 and 11); at 0.01 x the
    // first took 15.
    springs::Ties ties = springs::tie_stiff(
      d.given_springs,
      d.springs,
      d.pairs,
      active,
      [&d](const types::global_dof_index i) { return d.diagonal(i); },
      1.);
    std::vector<ContactRow>        extended;
    const std::vector<ContactRow> *rows = &d.pairs;
    std::vector<bool>              held = active;
    if (!ties.for_constraints.empty())
      {
        extended = d.pairs;
        extended.insert(extended.end(),
                        ties.for_constraints.begin(),
                        ties.for_constraints.end());
        held.resize(extended.size(), true);
        rows = &extended;
      }
    d.operator_springs = std::move(ties.kept);
    d.totals.n_tied += ties.rows.size();
    d.n_tied_last = ties.rows.size();
    ActiveSetSolver::make_constraints(d.base, *rows, held, d.constraints);
    // The condensed right hand side T^T (d + sum k g_w w - K g), g the
    // inhomogeneities; with couplings T^T (I - B (M + E B)^-1 E) (...).
    // (Without couplings no equations: the multipliers are made after the
    // solve.)
    d.coupling = std::make_unique<RowMultipliers>(
      d.base,
      *rows,
      d.couplings.empty() ? std::vector<bool>(rows->size(), false) : held,
      d.couplings);
    const StiffnessResidual residual =
      [&](Vector<double> &r, const Vector<double> &u, const Vector<double> &f) {
        d.product(r, u);
        r.sadd(-1., 1., f);
      };
    const Vector<double> b = springs::condensed_load(d.operator_springs,
                                                     residual,
                                                     *d.rhs,
                                                     d.constraints,
                                                     [&](Vector<double> &r) {
                                                       d.coupling->project(r);
                                                     });
    d.condensation += clock.wall_time();

    // A hierarchy is kept while the CG iterations it costs beyond its rate
    // on its own set (iterations per decade of the residual) stay fewer
    // than a new one's set-up costs in CG iterations (setup_in_iterations).
    // A hierarchy of this very set is never stale (the influence solves of
    // the error bars repeat the loop's last set: measured on the 3D knee at
    // 2.3e5 dofs, the rule below rebuilt it twice there, since the loop's
    // exact last solve converges at another rate than the loose first one).
    const bool not_the_hierarchys =
      d.has_amg && (active != d.amg_active || !ties.rows.empty());
    const bool stale = not_the_hierarchys && d.rate_at_build > 0 &&
                       d.last_iterations - d.last_decades * d.rate_at_build >
                         setup_in_iterations;
    // With springs, a set that moved by more than 5 % of its rows from the
    // hierarchy's gets a new one: the friction loop moves a third to all of
    // them in its first iterations (3D knee, 1.25e5 dofs: a kept hierarchy then
    // took 300 to 500 CG iterations, a new one 150; a set-up costs about
    // 30), the frictionless loop a few rows.
    // So does a set whose tied springs changed dofs (3D knee, 2.3e5 dofs:
    // kept across such a change, with the rows within 5 %, hierarchies
    // ran out of their budgets of 240 to 460 iterations; fresh ones took
    // 150 to 280).
    unsigned int n_changed = 0, n_held = 0;
    for (std::size_t i = 0; i < active.size(); ++i)
      {
        n_held += active[i];
        n_changed += active[i] != (i < d.amg_active.size() && d.amg_active[i]);
      }
    std::vector<types::global_dof_index> tied;
    for (const auto &row : ties.for_constraints)
      tied.push_back(row.eliminated);
    // (Only with springs: the frictionless loop keeps the rule above,
    // which its measured times were tuned with; with these rules as well
    // the 3D knee at 1.25e5 dofs without friction took 23.5 s against 11.3
    // in its first case, 10 set-ups in 11 solves.)
    const bool with_springs = !d.given_springs.empty();
    const bool moved =
      with_springs && (n_changed > 0.05 * n_held || tied != d.amg_tied);
    // Every rank counts the same iterations and holds the same sets, so
    // every rank decides alike (the set-up is collective).
    // The loop's exact solve of a set that is not the hierarchy's gets a
    // new one whatever the rule above says (without springs): the exact solve
    // takes most of the loop's iterations, and the error bars' influence
    // solves repeat its set. The rule above decides from the last, loose
    // solve's excess, small beside the exact solve's (when it counted
    // measured times the machine's noise decided: the 3D knee at 232 989
    // dofs on two ranks, 2026-12-02:
    // five runs of one hierarchy took 255 CG iterations, one that had
    // rebuilt 182, its solve 20.3 s against 32.8). Taken from what every
    // rank knows alike: no broadcast.
    const double target_relative = std::max(d.settings.tolerance, d.accuracy);
    d.exact                      = target_relative <= d.settings.tolerance;
    const bool for_exact = !with_springs && d.exact && not_the_hierarchys;
    bool       fresh     = !d.has_amg || moved || for_exact || stale;
    if (fresh)
      {
        // Without springs a stale hierarchy is made anew, not recomputed on
        // its aggregates: measured on the Hertz sphere at 48 024 dofs
        // (prm/hertz_sphere_3d.prm, one process, a rebuild forced at every
        // change of the set), recomputing took 1 668 CG iterations, more
        // than keeping the first hierarchy throughout (268), new ones 81;
        // on two ranks at 223 854 dofs the rule's rebuilds, recomputed,
        // took 6 888 against one process's 390 with one hierarchy. The 3D
        // knee at 232 989 dofs: 164 iterations with a new hierarchy at
        // every change against 267 with one (20.0 against 21.1 s). With
        // springs recomputing was measured faster (build_amg()).
        d.build_amg(/*anew=*/d.has_amg && !with_springs);
        d.amg_active = active;
        d.amg_tied   = tied;
      }

    // Start from the previous solution on the free dofs, in place (a copy
    // and the start kept held two more vectors of every dof on every rank,
    // 16 MB at 1e6 dofs, through the solve).
    Vector<double> &y = d.x;
    for (const auto &line : d.constraints.get_lines())
      y(line.index) = 0;

    const double b_norm = std::max(b.l2_norm(), 1e-300);

    // With springs, a kept hierarchy gets a budget: 1.5 x the iterations a
    // fresh one would take (its rate per decade of the residual) and the
    // set-up's cost in iterations. Past it the hierarchy is rebuilt and CG
    // starts again, so that an operator that moved away from the hierarchy's
    // costs at most about a set-up and a fresh solve more (the rule above
    // decides from the last solve, and the friction loop changes its springs at
    // every iteration: 3D knee, 34 059 dofs, kept hierarchies took up to
    // 820 iterations where fresh ones took 100).
    const bool   budgeted     = with_springs && !fresh && d.rate_at_build > 0;
    const double budget_extra = budgeted ? setup_in_iterations : 0.;
    // Only a budgeted solve starts again.
    const Vector<double> start = budgeted ? y : Vector<double>();

    double        target = 0;
    SolverControl control(d.settings.max_iterations, 0., false, false);
    unsigned int  n_iterations = 0;
    double        rebuild_time = 0;
    clock.restart();
    const auto failed = [&](const SolverControl::NoConvergence &failure) {
      std::ostringstream message;
      message << "the iterative solver ("
              << (d.coupling->coupled() ? "GMRES" : "CG")
              << " with ML's AMG) did not converge "
              << "in " << n_iterations + failure.last_step
              << " iterations (Contact/Krylov iterations): residual "
              << failure.last_residual / b_norm << " of the target "
              << target / b_norm
              << " relative to the load; raise the limit, or take "
                 "Contact/Solver = sparse where the factor fits";
      AssertThrow(false, ExcMessage(message.str()));
    };
    try
      {
        d.krylov(y,
                 b,
                 control,
                 target,
                 b_norm,
                 target_relative,
                 budgeted ? d.rate_at_build : 0.,
                 budget_extra);
      }
    catch (const SolverControl::NoConvergence &failure)
      {
        if (!budgeted || failure.last_step >= d.settings.max_iterations)
          failed(failure);
        ++d.totals.n_over_budget;
        // Over budget: a new hierarchy, the rest of the iterations, from
        // the start again (from the iterate reached, the 3D knee at
        // 124 551 dofs took 300 to 660 iterations more where a fresh start
        // took 150).
        y            = start;
        n_iterations = failure.last_step;
        Timer rebuild;
        d.build_amg(/*anew=*/true);
        d.amg_active = active;
        d.amg_tied   = tied;
        fresh        = true;
        rebuild_time = rebuild.wall_time();
        control.set_max_steps(d.settings.max_iterations - n_iterations);
        try
          {
            d.krylov(y, b, control, target, b_norm, target_relative, 0, 0);
          }
        catch (const SolverControl::NoConvergence &failure)
          {
            failed(failure);
          }
      }
    const double time = clock.wall_time() - rebuild_time;
    d.totals.krylov += time;
    d.last_iterations = n_iterations + control.last_step();
    d.last_decades =
      std::log10(std::max(control.initial_value(), 1e-300) /
                 std::max(control.last_value(),
                          1e-300 * control.initial_value() + 1e-300));
    d.last_decades = std::max(d.last_decades, 0.5);
    if (fresh)
      d.rate_at_build = control.last_step() / d.last_decades;
    d.totals.n_iterations += d.last_iterations;
    d.totals.max_iterations =
      std::max(d.totals.max_iterations, d.last_iterations);
    ++d.totals.n_solves;
    d.totals.n_coupled += d.coupling->coupled();

    d.constraints.distribute(d.x);
    // What the path holds once its hierarchy, vectors and right hand
    // side exist: the figure its estimate is checked against.
    if (d.totals.n_solves == 1)
      d.measured_MB = iterative::resident_MB() - d.resident_at_start;
    if (!ties.for_multipliers.empty())
      std::copy(ties.for_multipliers.begin(),
                ties.for_multipliers.end(),
                extended.begin() + d.pairs.size());
    ActiveSetSolver::excess_and_multipliers(residual,
                                            *d.rhs,
                                            d.x,
                                            d.base,
                                            *rows,
                                            held,
                                            excess,
                                            lambda,
                                            d.operator_springs,
                                            d.couplings.empty()
                                              ? nullptr
                                              : d.coupling.get());
    springs::untie(ties, d.pairs.size(), excess, lambda);
  }



  void
  IterativeContactSystem::set_bound_couplings(
    const std::vector<BoundCoupling> &couplings)
  {
    implementation->couplings = couplings;
  }



  void
  IterativeContactSystem::set_springs(const std::vector<Spring> &springs)
  {
    implementation->given_springs = springs;
    implementation->springs = springs::on_dofs(springs, implementation->pairs);
  }



  double
  IterativeContactSystem::reference_solve(const std::vector<bool> &active,
                                          Vector<double>          &x)
  {
    Implementation &d = *implementation;
    // Keep the loop's state (its solution and figures); only the
    // hierarchy is new.
    const Vector<double> kept         = d.x;
    const double         was          = d.accuracy;
    const bool           was_of_start = d.accuracy_of_start;
    const auto           kept_totals  = d.totals;
    Timer                clock;
    d.x                 = 0;
    d.has_amg           = false;
    d.accuracy          = 0;
    d.accuracy_of_start = false;
    std::vector<double> excess, lambda;
    solve(active, excess, lambda);
    const double time      = clock.wall_time();
    d.reference_iterations = d.last_iterations;
    x                      = d.x;
    d.x                    = kept;
    d.accuracy             = was;
    d.accuracy_of_start    = was_of_start;
    d.totals               = kept_totals;
    return time;
  }



  bool
  IterativeContactSystem::holds_stiffness() const
  {
    return implementation->matrix == nullptr;
  }



  void
  IterativeContactSystem::stiffness_product(Vector<double>       &y,
                                            const Vector<double> &x) const
  {
    implementation->product(y, x);
  }



  double
  IterativeContactSystem::displacement_scale() const
  {
    return ActiveSetSolver::displacement_scale(implementation->pairs,
                                               implementation->x);
  }



  void
  IterativeContactSystem::solution(Vector<double> &x)
  {
    x = implementation->x;
  }



  std::map<std::string, double>
  IterativeContactSystem::statistics() const
  {
    const Implementation &d = *implementation;
    // What every rank holds whole for the contact, the replicated surface
    // (issue 38's memory bound counts it apart): the contact rows and C's
    // diagonal on their dofs and the lines'. Until 2026-12-02 C's rows of
    // all those dofs too (181 MB a rank at 1e6 DoFs); now each rank holds
    // the rows its part of the condensation reads (held_rows_MB).
    double replicated = d.line_diagonal.capacity() * sizeof(d.line_diagonal[0]);
    for (const auto &row : d.pairs)
      replicated +=
        sizeof(row) +
        (row.row.capacity() + row.reduced_row.capacity()) * sizeof(row.row[0]);
    double held =
      (d.line_columns.rows.capacity() + d.line_columns.columns.capacity()) *
        sizeof(types::global_dof_index) +
      d.line_columns.start.capacity() * sizeof(std::size_t);
    for (const auto &[row, entries] : d.held_rows)
      held += sizeof(row) + entries.capacity() * sizeof(entries[0]);
    return {{"amg_setups", d.totals.n_setups},
            {"amg_recomputed", d.totals.n_recomputed},
            {"amg_setup", d.totals.setup},
            {"krylov_solves", d.totals.n_solves},
            {"krylov_iterations", d.totals.n_iterations},
            {"krylov_iterations_max", d.totals.max_iterations},
            {"krylov_over_budget", d.totals.n_over_budget},
            {"tied_springs", d.totals.n_tied},
            {"coupled_solves", d.totals.n_coupled},
            {"krylov_time", d.totals.krylov},
            {"condensation", d.condensation},
            {"iterative_memory_MB", d.measured_MB},
            {"partition", d.partition_time},
            {"rows_assembly", d.rows_assembly},
            {"replicated_rows_MB", replicated / 1048576.},
            {"held_rows_MB", held / 1048576.},
            {"reference_krylov_iterations", d.reference_iterations}};
  }



  double
  IterativeContactSystem::estimated_bytes(const SparsityPattern &pattern,
                                          const bool             friction)
  {
    return bytes_of(pattern.n_rows(),
                    pattern.n_nonzero_elements(),
                    friction,
                    parallel::n_ranks() > 1);
  }



  double
  IterativeContactSystem::estimated_bytes(
    const TrilinosWrappers::SparsityPattern &pattern,
    const bool                               friction)
  {
    // On a distributed mesh the path holds C's rows on any number of
    // ranks.
    return bytes_of(pattern.n_rows(),
                    pattern.n_nonzero_elements(),
                    friction,
                    true);
  }



  double
  IterativeContactSystem::bytes_of(const double n,
                                   const double nnz,
                                   const bool   friction,
                                   const bool   holds_c)
  {
    // Trilinos' matrix of this rank's condensed rows (values and column
    // indices, 12 bytes an entry; condense() sums each row once), the
    // hierarchy (about 10 bytes per fine entry measured with plain
    // aggregation: 150 MB for the knee's 1.48e7 entries); the null space
    // twice (ML's copy), the CG and operator vectors and the condensed
    // right hand side: about 22 vectors. Several ranks or a distributed
    // mesh: each rank also holds its part of C in Trilinos (12, the
    // operator's); the vectors stay whole (replicated). With friction
    // GMRES's basis of this rank's rows.
    const double ranks = parallel::n_ranks();
    const double basis = friction ? 8. * gmres_basis * n / ranks : 0.;
    const double of_c  = holds_c ? 12. : 0.;
    return (12. + 10. + of_c) * nnz / ranks + 8. * 22 * n + basis;
  }
} // namespace knee_contact
