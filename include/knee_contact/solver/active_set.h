#ifndef knee_contact_active_set_h
#define knee_contact_active_set_h

#include <knee_contact/contact/contact_row.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/row_multipliers.h>
#include <knee_contact/solver/springs.h>
#include <knee_contact/solver/stiffness.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <array>
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * What the active-set loop found.
   */
  struct ContactSolution
  {
    std::vector<bool>   active;
    std::vector<double> lambda; // contact force of each pair [N/m], >= 0
    unsigned int        n_iterations = 0;
    /** Iteration at which a cycle switched on the safeguard; 0: never. */
    unsigned int safeguard_from = 0;
    bool         converged      = true;
    std::string  failure; // why not, if not converged
    double       complementarity = 0;
    /** The Contact/Tolerance the loop converged to (the KKT check's). */
    double tolerance       = 1e-10;
    double max_penetration = 0; // max (A x - g)_p [m]

    /**
     * With friction (solve_with_friction()), per pair: the tangential
     * multiplier [N/m in 2D, N in 3D] by its components along the pair's
     * tangents t_j (the force on the slave is -sum_j lambda_t,j t_j), the
     * slip t_j . (u_slave - u_master) less the tangential rows' gaps [m] of
     * a slipping pair (zero where it sticks or is open), and the status.
     * Empty without friction.
     */
    std::vector<TangentialVector> lambda_t;
    std::vector<TangentialVector> slip;
    /**
     * Along a load path (Load cases/Values of t with friction): per pair
     * the slip of this case is its increment since the previous case, and
     * this the sum of the increments' magnitudes since the first case [m].
     */
    std::vector<double> accumulated_slip;
    enum class Status
    {
      open,
      stick,
      slip
    };
    std::vector<Status> status;
    /**
     * Fixed-point updates of the Coulomb bounds and the slip directions
     * after the sets settled.
     */
    unsigned int n_bound_updates = 0;
  };

  /** "open", "stick" or "slip": the status as the CSVs write it. */
  inline std::string
  status_name(const ContactSolution::Status status)
  {
    switch (status)
      {
        case ContactSolution::Status::stick:
          return "stick";
        case ContactSolution::Status::slip:
          return "slip";
        default:
          return "open";
      }
  }

  /**
   * The friction law of one contact pair for solve_with_friction(): the
   * tangential multiplier is bounded by value x lambda_n (Coulomb, value =
   * mu) or by value (Tresca, value = bound [Pa] x the pair's length:
   * [N/m]); value 0: frictionless.
   */
  struct FrictionBound
  {
    bool   coulomb = false;
    double value   = 0;
    /**
     * How the pair's stick rows (which hold it while it sticks) combine
     * its normal and tangential rows, see stick_coefficients().
     */
    StickCoefficients stick{};
  };



  /**
   * The primal-dual active set method of step-41/42 for the seed's QP
   * min 1/2 x^T C x - x^T d subject to A x <= g (its eq. (13) and P_d).
   * Each iteration solves with the active rows as equalities (a
   * ContactSystem: condensed onto the contact unknowns, or step-41's
   * UMFPACK solve of the whole system), recovers the multipliers from the
   * residual d - C x, and updates
   *   A = {p : lambda_p + c ((A x)_p - g_p) > 0}.
   * deal.II has no contact solver for node pairs between bodies, so the
   * loop is written here.
   */
  class ActiveSetSolver
  {
  public:
    /**
     * Declare the solver's entries of the subsection "Contact", each bound
     * to the member it sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /**
     * After parsing: the active-set constant in units of
     * @p max_youngs_modulus, the stiffness scale of the scene;
     * @p min_youngs_modulus scales the 3D friction rule's constant.
     */
    void
    check_parameters(const double max_youngs_modulus,
                     const double min_youngs_modulus);

    /**
     * How the linear systems of the loop are solved (see ContactSystem).
     */
    using LinearSolver = SolverPath;

    LinearSolver
    linear_solver() const
    {
      return solver;
    }

    /**
     * Whether to time one linear solve with the final active set held
     * fixed (the benchmark's reference).
     */
    bool
    measure_reference() const
    {
      return reference_solve;
    }

    /**
     * Contact/Coarse start levels: how many levels coarser a mesh the
     * first cycle's active set is guessed on (0: none).
     */
    unsigned int
    coarse_start_levels() const
    {
      return coarse_levels;
    }

    /** The iterative path's settings. */
    const KrylovSettings &
    krylov_settings() const
    {
      return krylov;
    }

    /** The sparse path's factor library (Contact/Direct factor). */
    DirectFactor
    direct_factor() const
    {
      return factor;
    }

    /** Override the scene's Contact/Direct factor (tests compare them). */
    void
    set_direct_factor(const DirectFactor direct_factor)
    {
      factor = direct_factor;
    }

    /** Override the scene's Contact/Solver (tests compare the two). */
    void
    set_linear_solver(const LinearSolver linear_solver)
    {
      solver = linear_solver;
    }

    /**
     * Run the loop on @p system. @p force_scale is |d|_inf (the load
     * scale of the round-off test for unloaded contact). @p guess marks
     * the pairs to start active (the contact zone of a coarser mesh, the
     * active set of the previous load case); empty: start from the pairs
     * that touch (g_p <= 0). @p log receives one line per
     * iteration. The solution is then system.solution().
     */
    ContactSolution
    solve(ContactSystem                   &system,
          const double                     force_scale,
          const AffineConstraints<double> &base,
          const std::vector<ContactRow>   &pairs,
          const RigidModeCheck            &rigid_modes,
          const std::vector<bool>         &guess,
          std::ostream                    &log) const;

    /**
     * The same loop with friction: @p rows are the n normal rows, the n
     * tangential rows and the 2n rows that hold sticking pairs
     * (ContactPairs::solver_rows(); the tangential rows' gaps are where
     * the pairs stuck last, so their excess is the slip of this step),
     * @p bounds the law of each pair, @p rhs the load vector d (the slip
     * forces are added to it in each iteration). Each iteration solves
     * with the active normal rows and the sticking pairs' rows as
     * equalities and the slipping pairs' tangential forces prescribed,
     * then decides: normal contact as solve(); a sticking pair slips where
     * |lambda_t| exceeds its bound, a slipping pair sticks where it would
     * slip against its force, a pair that comes into contact slips the way
     * it moved while open; the Coulomb bound mu lambda_n of the last
     * iterate (a fixed point on the bound: every system stays symmetric
     * positive definite, so every solver path serves). The pairs marked in
     * @p guess (if not empty) start in contact and sticking, else those
     * with zero gap. A body that friction cannot hold is refused naming
     * the ratio of the tangential to the normal force it needs.
     */
    ContactSolution
    solve_with_friction(ContactSystem                    &system,
                        const Vector<double>             &rhs,
                        const AffineConstraints<double>  &base,
                        const std::vector<ContactRow>    &rows,
                        const std::vector<FrictionBound> &bounds,
                        const RigidModeCheck             &rigid_modes,
                        const std::vector<bool>          &guess,
                        std::ostream                     &log) const;

    /**
     * Where contact alone must hold a body: @p close the pairs of
     * @p candidates (not in contact yet) in the order of their gaps,
     * doubling their number, until no rigid motion is free under @p base
     * and the rows marked in @p active (which @p close updates).
     */
    static void
    close_until_held(const AffineConstraints<double>         &base,
                     const std::vector<ContactRow>           &rows,
                     std::vector<unsigned int>                candidates,
                     const RigidModeCheck                    &rigid_modes,
                     const std::vector<bool>                 &active,
                     const std::function<void(unsigned int)> &close);

    /**
     * The first step of a cold start (no guess): the penetration a pair
     * must exceed to enter the set in the first iteration. On an interface
     * whose first solve held it at points (more than
     * first_step_spread times as many pairs penetrate as were in contact)
     * a fraction 1 - first_step_length of the deepest penetration there
     * (@p excess of the pairs p < in_contact.size() not @p in_contact, the
     * first rows of @p rows); elsewhere 0. Why: a body held at a point
     * sinks by the point's local compliance, F / (E h), which grows as the
     * mesh is refined, and its penetration zone overestimates the contact
     * zone by as much (see the code).
     */
    static std::vector<double>
    first_step_thresholds(const std::vector<ContactRow> &rows,
                          const std::vector<double>     &excess,
                          const std::vector<bool>       &in_contact);

    /**
     * The length of the first step from bodies held at points, as a
     * fraction of the deepest penetration, and the ratio of penetrating to
     * contact pairs that says an interface was held at points
     * (first_step_thresholds()).
     */
    static constexpr double first_step_spread = 10;
    static constexpr double first_step_length = 0.03;

    /**
     * One sparsity pattern for the condensed systems of every active set of
     * @p pairs under @p base (see the comment in the code);
     * @p cycles_allowed with friction, whose rows are not all active
     * together; @p spring_rows: groups of rows a spring may combine
     * (ContactSystem::Spring: the tangential rows of a 3D frictional pair),
     * whose dofs the pattern couples with each other too.
     */
    static void
    make_sparsity_pattern(
      const DynamicSparsityPattern                 &mesh_pattern,
      const AffineConstraints<double>              &base,
      const std::vector<ContactRow>                &pairs,
      SparsityPattern                              &sparsity_pattern,
      const bool                                    cycles_allowed = false,
      const std::vector<std::vector<unsigned int>> &spring_rows    = {});

    /**
     * The same on a distributed mesh: each rank expands its rows of
     * @p mesh_pattern (C's pattern, made from the cells each rank owns);
     * @p sparsity_pattern gets this rank's rows of every set's condensed
     * system (the lines and @p pairs are every rank's).
     */
    static void
    make_sparsity_pattern(
      const TrilinosWrappers::SparsityPattern      &mesh_pattern,
      const AffineConstraints<double>              &base,
      const std::vector<ContactRow>                &pairs,
      TrilinosWrappers::SparsityPattern            &sparsity_pattern,
      const bool                                    cycles_allowed = false,
      const std::vector<std::vector<unsigned int>> &spring_rows    = {});

    /**
     * The constraints of @p base plus the active rows of @p pairs, closed.
     */
    static void
    make_constraints(const AffineConstraints<double> &base,
                     const std::vector<ContactRow>   &pairs,
                     const std::vector<bool>         &active,
                     AffineConstraints<double>       &constraints);

    /**
     * The multipliers lambda_p of the active pairs from the residual
     * r = d - C x: C0^T r = C0^T A^T lambda at the eliminated dofs, where C0
     * maps free dofs to all under Gamma_u/Gamma_o.
     */
    static std::vector<double>
    multipliers(const Vector<double>            &residual,
                const AffineConstraints<double> &base,
                const std::vector<ContactRow>   &pairs,
                const std::vector<bool>         &active);

    /**
     * What a path that solves for the whole x reports (step-41, sparse):
     * the multipliers from the residual d - C x (multipliers(); C through
     * @p residual), less the
     * forces of the @p springs set, and the excess (A x - g)_p of every
     * pair from its jump; with @p coupled those of the coupled system
     * (the RowMultipliers the solve made, not made twice).
     */
    static void
    excess_and_multipliers(const StiffnessResidual         &residual,
                           const Vector<double>            &rhs,
                           const Vector<double>            &x,
                           const AffineConstraints<double> &base,
                           const std::vector<ContactRow>   &pairs,
                           const std::vector<bool>         &active,
                           std::vector<double>             &excess,
                           std::vector<double>             &lambda,
                           const std::vector<SpringTerm>   &springs = {},
                           const RowMultipliers            *coupled = nullptr);

    /**
     * max |x_i| over the contact unknowns (every free dof of a row that
     * can be active), the scale of the complementarity residual.
     */
    static double
    displacement_scale(const std::vector<ContactRow> &pairs,
                       const Vector<double>          &x);

  private:
    unsigned int max_iterations = 50;
    /** Active set constant as the scene gives it, in units of E_max. */
    double c_relative = 100;
    double c          = 0;
    /** The softest material's Young's modulus [Pa]. */
    double         e_minimum       = 0;
    double         tolerance       = 1e-10;
    bool           safeguard       = true;
    LinearSolver   solver          = LinearSolver::automatic;
    bool           reference_solve = false;
    unsigned int   coarse_levels   = 0;
    KrylovSettings krylov;
    DirectFactor   factor = DirectFactor::automatic;
  };
} // namespace knee_contact

#endif
