#include <knee_contact/core/interruption.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/sparse_cholesky.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/trilinos_precondition.h>
#include <deal.II/lac/trilinos_sparse_matrix.h>

#include <ml_MultiLevelPreconditioner.h>
#include <mpi.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace knee_contact
{
  namespace iterative
  {
    /**
     * Trilinos' Epetra objects need MPI; a serial run initialises it only
     * when this path is taken (and finalises it at exit).
     *
     * A process not started by mpirun is an Open MPI "singleton". By
     * default it forks a daemon (orted) and keeps a session folder under
     * TMPDIR (ompi.<host>.<uid>/jf.<n>) that only MPI_Finalize removes: a
     * run stopped by a signal, whose handler must _exit, left one folder
     * per run in /tmp (measured). So a singleton runs isolated (no daemon)
     * with its session folder inside a private folder of its own, which
     * the interruption handler removes on a signal and the exit handler
     * after MPI_Finalize. Only a SIGKILL can leave it.
     */
    void
    ensure_mpi()
    {
      int initialised = 0;
      MPI_Initialized(&initialised);
      if (initialised)
        return;
      static std::string session_folder;
      if (std::getenv("OMPI_COMM_WORLD_SIZE") == nullptr)
        {
          // Open MPI's shared-memory and network transports would map
          // memory and plugins (and fail under an address-space limit,
          // measured), so only its "self" transport is loaded unless the
          // user chose otherwise.
          setenv("OMPI_MCA_btl", "self", 0);
          setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
          if (std::getenv("OMPI_MCA_orte_tmpdir_base") == nullptr)
            {
              const char *tmpdir = std::getenv("TMPDIR");
              std::string pattern =
                (tmpdir != nullptr && tmpdir[0] == '/' ? tmpdir : "/tmp");
              pattern += "/knee_contact-mpi-XXXXXX";
              if (mkdtemp(pattern.data()) != nullptr)
                {
                  session_folder = pattern;
                  interruption::register_folder(session_folder);
                  setenv("OMPI_MCA_orte_tmpdir_base",
                         session_folder.c_str(),
                         1);
                }
            }
        }
      int provided = 0;
      MPI_Init_thread(nullptr, nullptr, MPI_THREAD_SERIALIZED, &provided);
      std::atexit([]() {
        int finalised = 0;
        MPI_Finalized(&finalised);
        if (!finalised)
          MPI_Finalize();
        if (!session_folder.empty())
          {
            std::error_code ignored;
            std::filesystem::remove_all(session_folder, ignored);
            interruption::unregister_folder(session_folder);
          }
      });
    }

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
     */
    class CondensedOperator
    {
    public:
      CondensedOperator(const SparseMatrix<double>      &matrix,
                        const AffineConstraints<double> &constraints)
        : matrix(matrix)
        , constraints(constraints)
        , spread(matrix.m())
      {}

      void
      vmult(Vector<double> &dst, const Vector<double> &src) const
      {
        spread = src;
        sparse_cholesky::distribute_homogeneous(constraints, spread);
        matrix.vmult(dst, spread);
        sparse_cholesky::condense_homogeneous(constraints, dst);
        for (const auto &line : constraints.get_lines())
          dst(line.index) = matrix.diag_element(line.index) * src(line.index);
        ++n_products;
      }

      mutable unsigned int n_products = 0;

    private:
      const SparseMatrix<double>      &matrix;
      const AffineConstraints<double> &constraints;
      mutable Vector<double>           spread;
    };
  } // namespace iterative



  class IterativeContactSystem::Implementation
  {
  public:
    Implementation(const SparseMatrix<double>        &matrix,
                   const AffineConstraints<double>   &base,
                   const std::vector<ContactRow>     &pairs,
                   const std::vector<Vector<double>> &modes,
                   const unsigned int                 components,
                   const KrylovSettings              &settings)
      : matrix(matrix)
      , base(base)
      , pairs(pairs)
      , components(components)
      , settings(settings)
      , x(matrix.m())
    {
      // ML reads the near null space as one column-major array.
      null_space.resize(modes.size() * matrix.m());
      for (unsigned int k = 0; k < modes.size(); ++k)
        std::copy(modes[k].begin(),
                  modes[k].end(),
                  null_space.begin() + k * matrix.m());
      n_modes = modes.size();
    }

    const SparseMatrix<double>      &matrix;
    const AffineConstraints<double> &base;
    const std::vector<ContactRow>   &pairs;
    const unsigned int               components;
    const KrylovSettings             settings;
    const Vector<double>            *rhs = nullptr;
    std::vector<double>              null_space;
    unsigned int                     n_modes = 0;

    AffineConstraints<double>         constraints;
    TrilinosWrappers::SparseMatrix    amg_matrix;
    TrilinosWrappers::PreconditionAMG amg;
    bool                              has_amg = false;
    Vector<double>                    x;
    double                            accuracy = 0;
    bool                              exact    = false;
    /** CG iterations per decade of the residual: after the last set-up,
     * and of the last solve. */
    double rate_at_build = 0, last_decades = 1;

    // Figures.
    double       resident_at_start = 0, measured_MB = 0;
    unsigned int reference_iterations = 0;
    double       condensation = 0, time_per_product = 0;
    unsigned int last_iterations = 0;
    /** The loop's totals for statistics() (the reference solve keeps them
     * as they were). */
    struct Totals
    {
      double       setup = 0, krylov = 0;
      unsigned int n_setups = 0, n_solves = 0, n_iterations = 0,
                   max_iterations = 0;
    } totals;

    void
    build_amg();
  };



  void
  IterativeContactSystem::Implementation::build_amg()
  {
    Timer clock;
    // The old hierarchy and matrix go first: kept while the new ones were
    // made, a rebuild (and the benchmark's reference solve) held two
    // hierarchies, about 10 bytes per matrix entry more than the
    // estimate's 22.
    amg.clear();
    amg_matrix.clear();
    {
      // The condensed matrix of this active set: deal.II condenses (on the
      // pattern that holds every set), Trilinos takes a copy, the deal.II
      // one goes.
      SparseMatrix<double> condensed(matrix.get_sparsity_pattern());
      condensed.copy_from(matrix);
      constraints.condense(condensed);
      amg_matrix.reinit(condensed, 0., true);
    }
    // The null space on the constrained dofs is zero: their rows are
    // decoupled.
    std::vector<double> modes = null_space;
    for (const auto &line : constraints.get_lines())
      for (unsigned int k = 0; k < n_modes; ++k)
        modes[k * matrix.m() + line.index] = 0;

    // Aggregation AMG for elasticity (one V-cycle, Chebyshev smoothing of
    // degree 2, coarsest level direct), with the rigid motions as the near
    // null space: deal.II 9.4's AdditionalData carries only translations,
    // so ML gets its own list. Plain aggregation (no prolongator
    // smoothing): measured on the 3D knee's tetrahedra (34 059 and 232 989
    // dofs), smoothed aggregation saved 5 % of the CG iterations but took
    // 2.3 times the hierarchy's memory (770 against 330 MB at 2.3e5 dofs)
    // and 20 % more time; Gauss-Seidel smoothing 25 % fewer iterations at
    // twice the time.
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
    list.set("null space: vectors", modes.data());
    amg.initialize(amg_matrix, list);
    has_amg = true;
    ++totals.n_setups;
    totals.setup += clock.wall_time();
  }



  IterativeContactSystem::IterativeContactSystem(
    const SparseMatrix<double>        &matrix,
    const AffineConstraints<double>   &base,
    const std::vector<ContactRow>     &pairs,
    const std::vector<Vector<double>> &modes,
    const unsigned int                 components,
    const KrylovSettings              &settings)
  {
    iterative::ensure_mpi();
    implementation = std::make_unique<Implementation>(
      matrix, base, pairs, modes, components, settings);
    implementation->resident_at_start = iterative::resident_MB();
  }



  IterativeContactSystem::~IterativeContactSystem() = default;



  void
  IterativeContactSystem::set_rhs(const Vector<double> &rhs)
  {
    implementation->rhs = &rhs;
  }



  void
  IterativeContactSystem::set_accuracy(const double relative)
  {
    implementation->accuracy = relative;
  }



  bool
  IterativeContactSystem::last_solve_exact() const
  {
    return implementation->exact;
  }



  void
  IterativeContactSystem::solve(const std::vector<bool> &active,
                                std::vector<double>     &excess,
                                std::vector<double>     &lambda)
  {
    Implementation &d = *implementation;
    Assert(d.rhs != nullptr, ExcMessage("set_rhs() was not called"));
    Timer clock;
    ActiveSetSolver::make_constraints(d.base, d.pairs, active, d.constraints);
    // The condensed right hand side T^T (d - C g), g the inhomogeneities.
    const Vector<double> b =
      sparse_cholesky::condense(d.matrix, *d.rhs, d.constraints);
    d.condensation += clock.wall_time();

    // A hierarchy is kept while the CG iterations it costs beyond its rate
    // on its own set (iterations per decade of the residual) stay cheaper
    // than a new one (measured time per product against the measured
    // set-up).
    const bool stale = d.has_amg && d.time_per_product > 0 &&
                       (d.last_iterations - d.last_decades * d.rate_at_build) *
                           d.time_per_product >
                         d.totals.setup / d.totals.n_setups;
    const bool fresh = !d.has_amg || stale;
    if (fresh)
      d.build_amg();

    // Start from the previous solution on the free dofs.
    Vector<double> y = d.x;
    for (const auto &line : d.constraints.get_lines())
      y(line.index) = 0;

    const double target_relative = std::max(d.settings.tolerance, d.accuracy);
    d.exact                      = target_relative <= d.settings.tolerance;
    const double b_norm          = std::max(b.l2_norm(), 1e-300);

    iterative::CondensedOperator operation(d.matrix, d.constraints);
    // An inexact solve must still resolve what the new set changed: its
    // residual falls at least tenfold from the warm start's (an inexact
    // Newton step's forcing term of 0.1). Without this a start already
    // below the loose target took no iteration, the loop decided on the
    // old set's solution and added back the pairs it had just released
    // (measured: the Hertz sphere at 3.4e5 dofs alternated for 20
    // iterations). A hundredfold cost 23 % more CG iterations on the knee
    // at 2.3e5 dofs (438 against 355) and 8 % on that Hertz sphere (795
    // against 733, both converging in 22 active-set iterations).
    Vector<double> start_residual(b.size());
    operation.vmult(start_residual, y);
    start_residual.sadd(-1., 1., b);
    const double  target = std::max(d.settings.tolerance * b_norm,
                                   std::min(target_relative * b_norm,
                                            1e-1 * start_residual.l2_norm()));
    SolverControl control(d.settings.max_iterations, target, false, false);
    SolverCG<Vector<double>> cg(control);
    clock.restart();
    try
      {
        cg.solve(operation, y, b, d.amg);
      }
    catch (const SolverControl::NoConvergence &failure)
      {
        std::ostringstream message;
        message << "the iterative solver (CG with ML's AMG) did not converge "
                << "in " << failure.last_step
                << " iterations (Contact/Krylov iterations): residual "
                << failure.last_residual / b_norm << " of the target "
                << target / b_norm
                << " relative to the load; raise the limit, or take "
                   "Contact/Solver = sparse where the factor fits";
        AssertThrow(false, ExcMessage(message.str()));
      }
    const double time = clock.wall_time();
    d.totals.krylov += time;
    d.time_per_product = time / std::max<unsigned int>(1, operation.n_products);
    d.last_iterations  = control.last_step();
    d.last_decades =
      std::log10(std::max(control.initial_value(), 1e-300) /
                 std::max(control.last_value(),
                          1e-300 * control.initial_value() + 1e-300));
    d.last_decades = std::max(d.last_decades, 0.5);
    if (fresh)
      d.rate_at_build = d.last_iterations / d.last_decades;
    d.totals.n_iterations += d.last_iterations;
    d.totals.max_iterations =
      std::max(d.totals.max_iterations, d.last_iterations);
    ++d.totals.n_solves;

    d.x = y;
    d.constraints.distribute(d.x);
    // What the path holds once its hierarchy, vectors and right hand
    // side exist: the figure its estimate is checked against.
    if (d.totals.n_solves == 1)
      d.measured_MB = iterative::resident_MB() - d.resident_at_start;
    ActiveSetSolver::excess_and_multipliers(
      d.matrix, *d.rhs, d.x, d.base, d.pairs, active, excess, lambda);
  }



  double
  IterativeContactSystem::reference_solve(const std::vector<bool> &active,
                                          Vector<double>          &x)
  {
    Implementation &d = *implementation;
    // Keep the loop's state (its solution and figures); only the
    // hierarchy is new.
    const Vector<double> kept        = d.x;
    const double         was         = d.accuracy;
    const auto           kept_totals = d.totals;
    Timer                clock;
    d.x        = 0;
    d.has_amg  = false;
    d.accuracy = 0;
    std::vector<double> excess, lambda;
    solve(active, excess, lambda);
    const double time      = clock.wall_time();
    d.reference_iterations = d.last_iterations;
    x                      = d.x;
    d.x                    = kept;
    d.accuracy             = was;
    d.totals               = kept_totals;
    return time;
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
    return {{"amg_setups", d.totals.n_setups},
            {"amg_setup", d.totals.setup},
            {"krylov_solves", d.totals.n_solves},
            {"krylov_iterations", d.totals.n_iterations},
            {"krylov_iterations_max", d.totals.max_iterations},
            {"krylov_time", d.totals.krylov},
            {"condensation", d.condensation},
            {"iterative_memory_MB", d.measured_MB},
            {"reference_krylov_iterations", d.reference_iterations}};
  }



  double
  IterativeContactSystem::estimated_bytes(const SparsityPattern &pattern)
  {
    const double n = pattern.n_rows(), nnz = pattern.n_nonzero_elements();
    // Trilinos' copy of the condensed matrix (values and column indices,
    // 12 bytes an entry), beside it first the deal.II condensed values
    // (8 bytes an entry, freed), then the hierarchy (about 10 bytes per
    // fine entry measured with plain aggregation: 150 MB for the knee's
    // 1.48e7 entries); the null space twice (ML's copy), the CG and operator
    // vectors and the condensed right hand side: about 22 vectors.
    return 12. * nnz + 10. * nnz + 8. * 22 * n;
  }
} // namespace knee_contact
