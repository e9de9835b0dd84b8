#ifndef knee_contact_contact_system_h
#define knee_contact_contact_system_h

#include <knee_contact/contact/contact_row.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/solver/sparse_factor.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <functional>
#include <map>
#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace dealii
{
  namespace TrilinosWrappers
  {
    class SparsityPattern;
  }
} // namespace dealii

namespace knee_contact
{
  using namespace dealii;

  /**
   * The linear algebra of one active-set iteration, the solver seam: given
   * which contact rows hold as equalities, solve
   *   min 1/2 x^T C x - x^T d  subject to  Gamma_u/Gamma_o/hanging-node
   *   constraints and a'_p . x = g'_p for the active pairs p,
   * and report each pair's excess (A x - g)_p and the active multipliers.
   * ActiveSetSolver runs the same loop on any implementation.
   *
   * The classes see only matrices and rows (no geometry), so they do not
   * depend on the dimension.
   */
  class ContactSystem
  {
  public:
    virtual ~ContactSystem() = default;

    DeclExceptionMsg(ExcNotPositiveDefinite,
                     "the stiffness matrix with the contact unknowns held "
                     "is singular");

    /**
     * A load case: the load vector d of the following solves (the matrix and
     * the constraints stay). Must be called before the first solve().
     */
    virtual void
    set_rhs(const Vector<double> &rhs) = 0;

    /**
     * Solve with the rows of the pairs marked in @p active as equalities;
     * @p excess receives (A x - g)_p for every pair, @p lambda the
     * multiplier of every active pair (zero for the others).
     */
    virtual void
    solve(const std::vector<bool> &active,
          std::vector<double>     &excess,
          std::vector<double>     &lambda) = 0;

    /**
     * The gaps g_p of the rows (not their coefficients) have changed since
     * the last solve, as along a load path with friction (a sticking pair
     * is held where it is): the next solve uses the new gaps, on the same
     * factorisation. The default suits a path that reads the gaps at every
     * solve.
     */
    virtual void
    gaps_changed()
    {}

    /**
     * Inexact solves (the iterative path): the following solves may stop
     * at a residual of @p relative times the right hand side's norm (the
     * loop asks for little while the active set still changes), or with
     * @p of_start at @p relative times their start's residual (a solve
     * that resolves a change of a known solution, started from it:
     * start_from()); 0: solve to the path's final tolerance. Direct paths
     * are always exact.
     */
    virtual void
    set_accuracy(const double relative, const bool of_start = false)
    {
      (void)relative;
      (void)of_start;
    }

    /**
     * The next solve starts from @p x (the iterative path's warm start,
     * otherwise the last solve's solution; direct paths need none).
     */
    virtual void
    start_from(const Vector<double> &x)
    {
      (void)x;
    }

    /**
     * A spring of stiffness k [N/m^2 in 2D, N/m in 3D] on a combination
     * w = sum_r c_r a_r of rows (energy 1/2 k (w x - g_w)^2,
     * g_w = sum_r c_r g_r): the tangential Jacobian of a slipping
     * frictional pair, k (I - d d^T) in its tangent plane, for the
     * semismooth Newton step of ActiveSetSolver::solve_with_friction().
     */
    struct Spring
    {
      std::vector<std::pair<unsigned int, double>> rows;
      double                                       stiffness = 0;
    };

    /** Whether set_springs() is served; else the loop does without. */
    virtual bool
    takes_springs() const
    {
      return false;
    }

    /** The springs of the following solves (none by default). */
    virtual void
    set_springs(const std::vector<Spring> &springs)
    {
      AssertThrow(springs.empty(), ExcInternalError());
    }

    /**
     * The Coulomb bound of a slipping pair taken implicitly: the force
     * lambda_n sum_r c_r a_r on its tangential rows r (c_r = mu d_r, d the
     * slip force's direction), lambda_n the multiplier of its active
     * normal row, solved for with it (the Newton step of
     * ActiveSetSolver::solve_with_friction() on the bound mu lambda_n; the
     * system is no longer symmetric).
     */
    struct BoundCoupling
    {
      unsigned int                                 normal_row = 0;
      std::vector<std::pair<unsigned int, double>> rows;
    };

    /**
     * Whether set_bound_couplings() is served (an unsymmetric solve the
     * path can do at the cost of a symmetric one); else the loop takes the
     * bound mu lambda_n from the last solve (a fixed point).
     */
    virtual bool
    takes_bound_couplings() const
    {
      return false;
    }

    /**
     * The couplings of the following solves (none by default); each
     * normal_row must be active in them. The multipliers reported are
     * those of the coupled system.
     */
    virtual void
    set_bound_couplings(const std::vector<BoundCoupling> &couplings)
    {
      AssertThrow(couplings.empty(), ExcInternalError());
    }

    /** Whether the last solve met the final tolerance. */
    virtual bool
    last_solve_exact() const
    {
      return true;
    }

    /**
     * Whether the last solve held some springs as rows (infinitely stiff)
     * instead of taking them as given: the Newton step is then inexact
     * across the slip, and the loop accelerates the slip directions.
     */
    virtual bool
    springs_held_as_rows() const
    {
      return false;
    }

    /**
     * max |x_i| of the last solve over the contact unknowns (the free dofs
     * of the contact rows): the scale of the complementarity residual.
     */
    virtual double
    displacement_scale() const = 0;

    /**
     * The whole displacement of the last solve, every constraint
     * distributed.
     */
    virtual void
    solution(Vector<double> &x) = 0;

    /**
     * The path's own figures for summary.json and the benchmark (times of
     * its phases [s], sizes, memory [MB]), by name.
     */
    virtual std::map<std::string, double>
    statistics() const
    {
      return {};
    }

    /**
     * Whether this path holds C itself (stiffness_product()), where the
     * whole stiffness matrix is not made: the iterative path on several
     * ranks, which assembles the rows it holds.
     */
    virtual bool
    holds_stiffness() const
    {
      return false;
    }

    /** y = C x, whole on every rank, where holds_stiffness(). */
    virtual void
    stiffness_product(Vector<double> & /*y*/,
                      const Vector<double> & /*x*/) const
    {
      AssertThrow(false, ExcInternalError());
    }
  };



  /**
   * Today's path, as in step-41: each iteration copies C and d, condenses
   * the Gamma_u/Gamma_o lines and the active rows into them, factorises
   * with UMFPACK and solves. Its cost is (iterations x one factorisation).
   */
  class FullContactSystem : public ContactSystem
  {
  public:
    /**
     * @p matrix's pattern must hold every condensed system
     * (ActiveSetSolver::make_sparsity_pattern).
     */
    FullContactSystem(const SparseMatrix<double>      &matrix,
                      const AffineConstraints<double> &base,
                      const std::vector<ContactRow>   &pairs);

    /** Keeps a reference to @p rhs. */
    void
    set_rhs(const Vector<double> &rhs) override;

    /**
     * Springs are added to the matrix before the condensation (on the
     * pattern that couples each spring's dofs) and to the load.
     */
    bool
    takes_springs() const override
    {
      return true;
    }

    void
    set_springs(const std::vector<Spring> &springs) override;

    void
    solve(const std::vector<bool> &active,
          std::vector<double>     &excess,
          std::vector<double>     &lambda) override;

    double
    displacement_scale() const override;

    void
    solution(Vector<double> &x) override;

  private:
    const SparseMatrix<double>      &matrix;
    const Vector<double>            *rhs = nullptr;
    const AffineConstraints<double> &base;
    const std::vector<ContactRow>   &pairs;
    std::vector<Spring>              springs;
    SparseMatrix<double>             system_matrix;
    Vector<double>                   system_rhs;
    Vector<double>                   x;
  };



  /**
   * The condensed path: one sparse Cholesky factorisation per mesh, with
   * the contact unknowns c (every free dof of every contact row) ordered
   * last, gives the Schur complement S = C_cc - C_ci C_ii^-1 C_ic of the
   * interface from the trailing block of the factor; the active-set loop
   * then runs on the dense k x k problem S x_c = f (k = number of contact
   * unknowns, a few thousand at most in 2D), and one back substitution
   * recovers the interior. A further load case on the same mesh costs one
   * forward and one back substitution (set_rhs()).
   *
   * CHOLMOD factorises (supernodal, BLAS); METIS orders the interior.
   * Neither library takes a Schur complement of a given set of unknowns
   * from a factor, so the extraction and the dense active-set algebra are
   * written here. A body held only by contact makes C singular but leaves
   * C_ii regular: the factorised matrix is C + alpha I_c (the shift only
   * touches the trailing block, L_cc L_cc^T = S + alpha I_c), and S is
   * recovered by subtracting alpha.
   */
  class CondensedContactSystem : public ContactSystem
  {
  public:
    /**
     * Order, analyse and factorise C under @p base (closed); throws
     * ExcNotPositiveDefinite if C_ii is singular (a body that neither the
     * boundary conditions nor its contact unknowns can hold).
     * @p order: a fill-reducing ordering of all dofs computed by the caller
     * (the contact unknowns are moved to its end); empty: METIS on the
     * interior here.
     */
    CondensedContactSystem(const SparseMatrix<double>      &matrix,
                           const AffineConstraints<double> &base,
                           const std::vector<ContactRow>   &pairs,
                           const std::vector<int>          &order = {});
    ~CondensedContactSystem() override;

    /**
     * A load case: condense d onto the contact unknowns (one forward
     * substitution); must be called before solve().
     */
    void
    set_rhs(const Vector<double> &rhs) override;

    /**
     * Springs enter the dense loop: the rows they combine join the
     * multiplier system (from the first spring on, which sets it up
     * again), or S before the elimination.
     */
    bool
    takes_springs() const override
    {
      return true;
    }

    void
    set_springs(const std::vector<Spring> &springs) override;

    /**
     * Served by the multiplier loop: a coupling adds a column to its
     * P x P system (already LU-factorised each iteration), so the Newton
     * step on the bound costs what the fixed point did.
     */
    bool
    takes_bound_couplings() const override;

    void
    set_bound_couplings(const std::vector<BoundCoupling> &couplings) override;

    void
    solve(const std::vector<bool> &active,
          std::vector<double>     &excess,
          std::vector<double>     &lambda) override;

    double
    displacement_scale() const override;

    /** One back substitution. */
    void
    solution(Vector<double> &x) override;

    /** Number of contact unknowns k. */
    unsigned int
    n_contact_unknowns() const;

    /** Wall times [s] of the set-up phases (statistics()). */
    struct Timings
    {
      double ordering      = 0;
      double factorisation = 0;
      double schur         = 0;
      /** S~ = S + rho B^T B, its factor, W and G (multiplier loop). */
      double loop_setup   = 0;
      double condensation = 0;
      double dense        = 0;
      double expansion    = 0;
    };

    /**
     * Memory [MB] of the sparse factor (values and row indices) and of the
     * dense matrices (L_cc, S~'s factor, W, G), for the benchmark.
     */
    std::pair<double, double>
    memory_MB() const;

    std::map<std::string, double>
    statistics() const override;

  private:
    class Implementation;
    std::unique_ptr<Implementation> implementation;
  };



  /**
   * The sparse path: step-41's iteration (condense the active rows into C,
   * factorise, solve), made as cheap as a sparse factor allows. The
   * matrix's pattern holds the condensed system of every active set
   * (ActiveSetSolver::make_sparsity_pattern), so one METIS ordering and one
   * CHOLMOD symbolic analysis serve every iteration and load case of a
   * mesh; an iteration costs one numeric (supernodal) factorisation, and a
   * solve with the active set of the previous one (a further load case, a
   * repeated set) costs two triangular solves. Memory is that of the
   * sparse factor: no dense interface matrices, so it scales where the
   * condensed path does not (long contact zones, adaptive meshes).
   */
  class SparseContactSystem : public ContactSystem
  {
  public:
    /**
     * Order (METIS) and analyse (no factorisation yet).
     */
    SparseContactSystem(const SparseMatrix<double>      &matrix,
                        const AffineConstraints<double> &base,
                        const std::vector<ContactRow>   &pairs);

    /**
     * The same from C's @p pattern, before C is assembled: @p matrix (on
     * that pattern once assembled) is read from the first solve on.
     */
    SparseContactSystem(const SparseMatrix<double>      &matrix,
                        const SparsityPattern           &pattern,
                        const AffineConstraints<double> &base,
                        const std::vector<ContactRow>   &pairs);
    ~SparseContactSystem() override;

    void
    set_rhs(const Vector<double> &rhs) override;

    void
    solve(const std::vector<bool> &active,
          std::vector<double>     &excess,
          std::vector<double>     &lambda) override;

    /**
     * Springs enter the factorised matrix (C + sum k w w^T condensed, on
     * the pattern that couples each spring's dofs), the load and the
     * multipliers' residual: new stiffnesses or directions cost the next
     * solve a factorisation, new gaps a new load only.
     */
    bool
    takes_springs() const override
    {
      return true;
    }

    void
    set_springs(const std::vector<Spring> &springs) override;

    /**
     * A coupled solve runs GMRES on T^T (I - B (M + E B)^-1 E) K T
     * (RowMultipliers) preconditioned by the factor of its active set
     * (T^T K T, made anew where the set is not the factor's: no bordered
     * update), which leaves only the couplings' low-rank change to GMRES.
     */
    bool
    takes_bound_couplings() const override
    {
      return true;
    }

    void
    set_bound_couplings(const std::vector<BoundCoupling> &couplings) override;

    /**
     * The factor stays (the gaps enter only the constraints'
     * inhomogeneities, not the condensed matrix); the base solution is
     * made anew.
     */
    void
    gaps_changed() override;

    double
    displacement_scale() const override;

    void
    solution(Vector<double> &x) override;

    std::map<std::string, double>
    statistics() const override;

    /**
     * Factorise with MUMPS, distributed over the ranks, instead of CHOLMOD
     * on every rank whole (before the first solve; collective). CHOLMOD's
     * analysis stays for the estimates.
     */
    void
    use_mumps();

    /**
     * The fill-reducing ordering of every dof (perm[new] = dof), which the
     * condensed path reuses.
     */
    const std::vector<int> &
    ordering() const;

    /** Entries of the factor and flops of one factorisation. */
    double
    nnz_factor() const;
    double
    flops() const;

  private:
    class Implementation;
    std::unique_ptr<Implementation> implementation;
  };



  /**
   * The settings of the iterative path (Contact/Krylov ...).
   */
  struct KrylovSettings
  {
    /** Final relative residual |b - K y| / |b| of each solve. */
    double tolerance = 1e-12;
    /** CG iterations allowed per solve. */
    unsigned int max_iterations = 1000;
  };



  /**
   * The iterative path (as step-42's, for bodies in contact with each
   * other): each iteration's system, C with the Gamma_u/Gamma_o lines and
   * the active rows condensed (each active row eliminates its dof, the
   * master entries carried by an AffineConstraints), is solved by CG,
   * preconditioned by Trilinos ML's aggregation AMG (plain aggregation:
   * see build_amg()) with the rigid motions as near null space. The operator is
   * applied as T^T C T on the stiffness matrix (no copy of it per active set);
   * the AMG hierarchy is built on the condensed matrix of one active set and
   * kept while the extra CG iterations it costs on later sets stay below the
   * price of a new hierarchy (never rebuilt for the set it was built for); each
   * solve starts from the previous solution and stops
   * at the accuracy the loop asks for. Memory grows linearly with the dofs:
   * the condensed matrix in Trilinos' format, the hierarchy (about 0.8 of
   * it with plain aggregation) and a few vectors.
   */
  class IterativeContactSystem : public ContactSystem
  {
  public:
    /**
     * On one rank, from C whole. @p rigid_modes gives AMG's near null
     * space (RigidModeCheck::rigid_motions(), on this rank's rows) and
     * the dofs per vertex (the block size of the aggregation).
     */
    IterativeContactSystem(const SparseMatrix<double>      &matrix,
                           const AffineConstraints<double> &base,
                           const std::vector<ContactRow>   &pairs,
                           const RigidModeCheck            &rigid_modes,
                           const KrylovSettings            &settings);

    /**
     * Assembles C's rows: @p assemble(wanted, add) gives
     * add(dofs, cell matrix) for each cell with a dof wanted(dof) says yes
     * to (ElasticityAssembler::assemble_cells()).
     */
    using RowAssembly = std::function<void(
      const std::function<bool(const types::global_dof_index)> &,
      const std::function<void(const std::vector<types::global_dof_index> &,
                               const FullMatrix<double> &)> &)>;

    /**
     * On several ranks, from C's @p pattern: the path assembles the rows
     * it holds with @p assemble_rows (this rank's, and those of the dofs
     * a constraint can hold), so that C whole is never made.
     */
    IterativeContactSystem(const SparsityPattern           &pattern,
                           const RowAssembly               &assemble_rows,
                           const AffineConstraints<double> &base,
                           const std::vector<ContactRow>   &pairs,
                           const RigidModeCheck            &rigid_modes,
                           const KrylovSettings            &settings);

    /**
     * On a distributed mesh (DistributedMesh): @p pattern holds this
     * rank's rows of every set's condensed system
     * (ActiveSetSolver::make_sparsity_pattern on C's pattern of the owned
     * cells), on the DoF handler's ownership, which the path takes;
     * @p assemble_cells gives the cells this rank owns. C's rows of the
     * dofs a line can hold are gathered from their owners to every rank
     * (the lines, the contact rows and the vectors the loop reads are
     * every rank's, whole, as on a whole mesh).
     */
    IterativeContactSystem(const TrilinosWrappers::SparsityPattern &pattern,
                           const RowAssembly               &assemble_cells,
                           const AffineConstraints<double> &base,
                           const std::vector<ContactRow>   &pairs,
                           const RigidModeCheck            &rigid_modes,
                           const KrylovSettings            &settings);
    ~IterativeContactSystem() override;

    void
    set_rhs(const Vector<double> &rhs) override;

    void
    solve(const std::vector<bool> &active,
          std::vector<double>     &excess,
          std::vector<double>     &lambda) override;

    void
    set_accuracy(const double relative, const bool of_start = false) override;

    void
    start_from(const Vector<double> &x) override;

    /**
     * Springs enter the operator (k w w^T, applied, never formed), the
     * right hand side and the multipliers' residual; the AMG hierarchy is
     * that of C without them (with them the 3D knee's stance took more CG
     * iterations, not fewer: 4 828 against 3 143 in its first case). A
     * spring at least as stiff as C on its dofs is held as a row instead
     * (springs::tie_stiff()): each such spring is an outlying eigenvalue,
     * and the semismooth Newton step's springs reach 100 E_max h (3D knee,
     * 34 059 dofs: up to 4 682 CG iterations a solve before, at most 250
     * after).
     */
    bool
    takes_springs() const override
    {
      return true;
    }

    void
    set_springs(const std::vector<Spring> &springs) override;

    /**
     * A coupling enters the operator as the projection of RowMultipliers
     * (T^T (I - B (M + E B)^-1 E) C T, applied, never formed: one small
     * sparse solve per product, summed over the ranks), and the solve
     * takes GMRES (gmres_basis) with the same hierarchy.
     */
    bool
    takes_bound_couplings() const override
    {
      return true;
    }

    void
    set_bound_couplings(const std::vector<BoundCoupling> &couplings) override;

    bool
    last_solve_exact() const override;

    bool
    springs_held_as_rows() const override;

    double
    displacement_scale() const override;

    void
    solution(Vector<double> &x) override;

    std::map<std::string, double>
    statistics() const override;

    /**
     * The benchmark's reference for this path: one linear solve with
     * @p active held, from a new hierarchy and a zero start to the final
     * tolerance, in @p x; returns its wall time (set-up included). The
     * hierarchy of the loop is replaced (no second one is held).
     */
    double
    reference_solve(const std::vector<bool> &active, Vector<double> &x);

    /** On several ranks (the second constructor). */
    bool
    holds_stiffness() const override;

    void
    stiffness_product(Vector<double>       &y,
                      const Vector<double> &x) const override;

    /**
     * Peak memory [bytes] the path adds to C's pattern (and on one rank to
     * C), from the pattern: the condensed copy while it is handed over,
     * Trilinos' matrix, the hierarchy and the Krylov vectors (measured:
     * doc/performance.md); with @p friction GMRES's basis.
     */
    static double
    estimated_bytes(const SparsityPattern &pattern, const bool friction);

    /**
     * The same on a distributed mesh, from every set's condensed pattern
     * (this rank's rows; its size is the whole pattern's): the path holds
     * C's rows there on any number of ranks. Measured at 1e6 DoFs:
     * doc/parallel.md, "The distributed mesh (begun)".
     */
    static double
    estimated_bytes(const TrilinosWrappers::SparsityPattern &pattern,
                    const bool                               friction);

    /**
     * GMRES's basis with bound couplings (restarted when it is full); it
     * is right preconditioned, so that its residual is the one CG's
     * targets are of. Measured on the 3D knee's stance (34 059 dofs): with
     * 30 vectors a final solve to Contact/Krylov tolerance = 1e-12 stalled
     * at 1.7e-12 (each restart begins from the true residual, which
     * round-off holds there), with 60 and 120 every solve converged.
     */
    static constexpr unsigned int gmres_basis = 60;

  private:
    /** estimated_bytes() from the size of the condensed pattern (@p n
     * rows, @p nnz entries); @p holds_c: the path holds C's rows. */
    static double
    bytes_of(const double n,
             const double nnz,
             const bool   friction,
             const bool   holds_c);

    /** All three: C whole (@p matrix) or its rows (@p assemble_rows),
     * on a whole @p pattern or on a distributed mesh's @p distributed_pattern.
     */
    IterativeContactSystem(
      const SparsityPattern                   *pattern,
      const TrilinosWrappers::SparsityPattern *distributed_pattern,
      const SparseMatrix<double>              *matrix,
      const RowAssembly                       *assemble_rows,
      const AffineConstraints<double>         &base,
      const std::vector<ContactRow>           &pairs,
      const RigidModeCheck                    &rigid_modes,
      const KrylovSettings                    &settings);

    class Implementation;
    std::unique_ptr<Implementation> implementation;
  };



  /**
   * How the active-set loop's linear algebra is done (Contact/Solver).
   */
  enum class SolverPath
  {
    automatic,
    condensed,
    sparse,
    iterative,
    step41
  };

  /** "automatic", "condensed", "sparse", "iterative", "step-41". */
  std::string
  solver_path_name(const SolverPath path);

  /**
   * The path plan_contact_system() chose from C's pattern, before C is
   * assembled, for make_contact_system().
   */
  struct SolverPlan
  {
    SolverPath path = SolverPath::automatic;
    /** Why (the log line's). */
    std::string reason;
    /** The estimates behind the choice (summary.json's "solver"). */
    std::map<std::string, double> figures;
    /** The sparse path's ordering and analysis made for the choice (the
     * sparse and condensed paths take them). */
    std::unique_ptr<SparseContactSystem> sparse;
    /** The sparse path's factor is MUMPS's. */
    bool mumps = false;
    /** The iterative path on several ranks: it assembles the rows it holds
     * (make_contact_system()'s @p rows), C whole is not made. */
    bool rows_only = false;
    /** The sparse path's estimate and the memory available (a condensed
     * path that cannot be made falls back to the sparse one). */
    double      sparse_bytes = 0, available = 0;
    std::string limit;
  };

  /** What make_contact_system() made. */
  struct SolverChoice
  {
    std::unique_ptr<ContactSystem> system;
    /** The path taken: condensed, sparse, iterative or step-41. */
    std::string name;
    /** The estimates behind the choice (summary.json's "solver"). */
    std::map<std::string, double> figures;
  };



  /**
   * The first half of the one factory of the solver seam: the path, from
   * C's pattern @p sparsity alone (before C is assembled into @p matrix,
   * which only the sparse path's analysis keeps a reference to). For
   * SolverPath::automatic it estimates, before allocating, the time
   * (flops) and peak memory of the condensed path (its dense interface
   * arrays, k^3 and P^3 work), of the sparse path (factor size and flops
   * from CHOLMOD's symbolic analysis, times the expected iterations) and
   * of the iterative path, and takes the cheapest that fits in the memory
   * available to the process (MemAvailable, the cgroup limit, ulimit -v); a
   * requested path that does not fit is switched, and if none fits the run
   * is refused in one line naming the estimate and the limit. @p factor:
   * the sparse path's factor library (MUMPS's is divided over the ranks, in
   * the estimates too). @p warm_start: the loop starts from a guess (a
   * refined mesh, a further load case), so fewer iterations are expected.
   */
  SolverPlan
  plan_contact_system(const SolverPath                 requested,
                      const SparsityPattern           &sparsity,
                      const SparseMatrix<double>      &matrix,
                      const AffineConstraints<double> &base,
                      const std::vector<ContactRow>   &pairs,
                      const DirectFactor               factor,
                      const bool                       warm_start);

  /**
   * The second half: the contact system of @p plan, from C assembled in
   * @p matrix, or where plan.rows_only from the rows @p rows assembles
   * (@p matrix is then not read). @p log gets one line saying which path
   * and why.
   */
  SolverChoice
  make_contact_system(SolverPlan                               &&plan,
                      const SparsityPattern                     &sparsity,
                      const SparseMatrix<double>                &matrix,
                      const IterativeContactSystem::RowAssembly *rows,
                      const AffineConstraints<double>           &base,
                      const std::vector<ContactRow>             &pairs,
                      const RigidModeCheck                      &rigid_modes,
                      const KrylovSettings                      &krylov,
                      std::ostream                              &log);



  /**
   * On a distributed mesh (DistributedMesh), where each rank holds its rows
   * of every set's condensed pattern @p pattern: the iterative path, the
   * one that runs on it (@p reason says why it was taken), with its memory
   * estimate (IterativeContactSystem::estimated_bytes()) checked against
   * the least any rank has; refused in one line if it does not fit.
   */
  SolverPlan
  plan_contact_system(const TrilinosWrappers::SparsityPattern &pattern,
                      const std::vector<ContactRow>           &pairs,
                      const std::string                       &reason);

  /**
   * The contact system of a plan for a distributed mesh: C's rows from the
   * cells each rank owns (@p rows), on @p pattern's rows.
   */
  SolverChoice
  make_contact_system(SolverPlan                               &&plan,
                      const TrilinosWrappers::SparsityPattern   &pattern,
                      const IterativeContactSystem::RowAssembly &rows,
                      const AffineConstraints<double>           &base,
                      const std::vector<ContactRow>             &pairs,
                      const RigidModeCheck                      &rigid_modes,
                      const KrylovSettings                      &krylov,
                      std::ostream                              &log);



  /**
   * One linear solve of C x = d with the Gamma_u/Gamma_o lines and the
   * rows of the @p active pairs as equalities, by CHOLMOD with the same
   * METIS ordering of vertices as CondensedContactSystem but no unknowns
   * forced last: the fastest solve the project has, the reference of the
   * benchmark. Returns the wall time of ordering, factorisation and solve.
   */
  double
  reference_solve(const SparseMatrix<double>      &matrix,
                  const Vector<double>            &rhs,
                  const AffineConstraints<double> &base,
                  const std::vector<ContactRow>   &pairs,
                  const std::vector<bool>         &active,
                  Vector<double>                  &x);
} // namespace knee_contact

#endif
