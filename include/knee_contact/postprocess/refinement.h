#ifndef knee_contact_refinement_h
#define knee_contact_refinement_h

#include <knee_contact/postprocess/problem_access.h>

#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/tria.h>

#include <string>

namespace knee_contact
{
  using namespace dealii;

  /**
   * How the mesh changes between cycles: every cell refined (global), or
   * the cells that carry the largest share of an a-posteriori error
   * estimate (adaptive), or both sequences one after the other (compare,
   * the speed-against-error study).
   */
  class Refinement
  {
  public:
    enum class Strategy
    {
      global,
      adaptive,
      compare
    };

    /**
     * Declare the subsection "Refinement", each entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /** After parsing: Number of adaptive cycles 0 means Number of cycles. */
    void
    check_parameters();

    /**
     * Refine @p triangulation (the one of @p state) once with @p strategy
     * (global or adaptive) using the solution on it. The adaptive indicator is
     * deal.II's Kelly estimator of the displacement gradient jumps, weighted by
     * sqrt(E) of each cell so that it estimates the energy norm error a(e,
     * e)^1/2 across materials; refinement by fixed fraction of the estimate.
     * With @p goal (one value per active cell: the cells' shares of a
     * quantity's goal-oriented error estimate, as Target quantity's peak
     * pressure has) that indicator takes Kelly's place: the refinement
     * serves the quantity.
     *
     * Returns false, with the mesh unchanged, where the Kelly estimate is
     * below round_off_level times a(u, u)^1/2: the mesh represents the
     * solution and refining it by rounding noise would mark cells that
     * depend on the machine.
     */
    template <int dim>
    bool
    refine(const Strategy            strategy,
           Triangulation<dim>       &triangulation,
           const ProblemAccess<dim> &state,
           const Vector<float>      *goal = nullptr) const;

    static std::string
    name(const Strategy strategy);

    /**
     * The relative Kelly estimate below which refine() calls the solution
     * resolved. A Q1 discretisation error of 1e-7 in the energy norm would
     * take a mesh size of about 1e-7 of the body (1e21 cells in 3D).
     * Measured: 5e-15 for an exact field (the uniaxial tetrahedral block),
     * 0.06 to 0.13 on the adaptive scenes of the tests (bonded blocks, the
     * 2D Hertz study); an iterative solve stops at a residual of 1e-12.
     */
    static constexpr double round_off_level = 1e-7;

    unsigned int n_cycles = 1;
    /** Cycles of the adaptive sequence (Strategy = adaptive or compare). */
    unsigned int n_adaptive_cycles = 0;
    Strategy     strategy          = Strategy::global;
    /**
     * Refinement/Target error (relative; 0: off) and the quantity it is
     * for, by the name the error estimates use (see
     * ContactProblem::cycle_quantities()).
     */
    double      target_error    = 0;
    std::string target_quantity = "peak pressure";

  private:
    /**
     * Mark the cells across each contact interface whose faces lie opposite
     * a marked boundary cell and are longer than its children will be, in
     * both directions until nothing changes, so the two sides stay about
     * equally fine (node-to-segment pairing handles any mismatch left).
     */
    template <int dim>
    void
    mark_partners(Triangulation<dim>      &triangulation,
                  const ContactInterfaces &interfaces) const;

    double refine_fraction = 0.5;
    /** Refinement/Indicator. */
    enum class Indicator
    {
      kelly,
      kelly_contact
    };
    Indicator indicator = Indicator::kelly_contact;
  };
} // namespace knee_contact

#endif
