#ifndef knee_contact_error_estimate_h
#define knee_contact_error_estimate_h

#include <limits>
#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  /**
   * The estimated discretisation error of one reported quantity.
   */
  struct ErrorEstimate
  {
    /** The quantity on the finest mesh (what the run reports). */
    double value = std::numeric_limits<double>::quiet_NaN();
    /**
     * The error bar: an estimate of |value - exact value of the model|, in
     * the quantity's units; NaN where the run has no estimate (one mesh).
     */
    double error = std::numeric_limits<double>::quiet_NaN();
    /** The value extrapolated to h -> 0 (NaN where not extrapolated). */
    double extrapolated = std::numeric_limits<double>::quiet_NaN();
    /** The observed order of convergence in h (NaN: not observed). */
    double order = std::numeric_limits<double>::quiet_NaN();
    /**
     * Whether the last three meshes show the quantity in its asymptotic
     * range (monotone, order at least 0.5); false: the bar is the
     * conservative fallback and the output flags it.
     */
    bool asymptotic = false;
    /** How the bar was made, for the output. */
    std::string basis = "one mesh: no estimate";
  };

  /** A cycle's reported quantities by name. */
  using Quantities = std::map<std::string, double>;

  /**
   * Error bars from the run's own sequence of meshes: Richardson
   * extrapolation with the observed order and Roache's grid convergence
   * index (Roache, J. Fluids Eng. 116, 1994; the procedure of Celik et al.,
   * J. Fluids Eng. 130, 078001, 2008), where the refinement ratio of
   * meshes that are not uniformly refined is r = (N_fine / N_coarse)^(1 /
   * dim) (N: degrees of freedom). With the last three meshes (values Q0,
   * Q1, Q2 from coarse to fine), e21 = Q2 - Q1, e10 = Q1 - Q0: where they
   * have one sign the order p solves p ln r21 = ln(e10 / e21) +
   * ln((r21^p - 1) / (r10^p - 1)) (Celik's equation without its absolute
   * value: differences that grow give p <= 0, no convergence), and the bar
   * is 1.25 |e21| / (r21^q - 1), q =
   * min(p, formal order) (the Richardson estimate with Roache's safety
   * factor for three meshes; an order above the formal one is not relied
   * on: measured on the two rings, the observed order of the pressure
   * falls from 1.5 to 1.0 along the sequence, and the bars with p were
   * 0.7 to 0.98 of the true error). Where the differences change sign or
   * p < 0.5 (not in the asymptotic range: an oscillating peak, a contact
   * edge jumping from vertex to vertex) the bar is 3 max(|e21|, |e10|) /
   * (r21^f - 1) with the formal order f: Roache's two-mesh factor, flagged.
   * With two meshes: 3 |e21| / (r21^f - 1), flagged. A difference at the
   * round-off of the value (1e-12) counts as converged: the bar is that
   * round-off, 1e-12 of the value. Formal orders (@p formal_order): 2 for the
   * energy, 1 for the others.
   *
   * Written here because no library the project uses estimates errors of
   * derived quantities from a mesh sequence (deal.II's ConvergenceTable
   * reports rates of known errors).
   *
   * @p cycles: each mesh's quantities, coarse to fine; a quantity missing
   * from a mesh is estimated from the meshes that have it.
   */
  std::map<std::string, ErrorEstimate>
  estimate_errors(const std::vector<Quantities> &cycles,
                  const std::vector<double>     &n_dofs,
                  const unsigned int             dim);

  /**
   * The energy's bar from one mesh: 1.25 @p eta_squared (the strain
   * recovery's estimate of a(u - u_h, u - u_h), recovered_error_products(),
   * with Roache's safety factor), at least the energy's round-off, 1e-13
   * of @p energy (an exactly represented solution: a patch test).
   */
  ErrorEstimate
  recovered_energy_estimate(const double energy, const double eta_squared);

  /**
   * One estimate from the last two or three values (see estimate_errors);
   * @p values and @p n_dofs coarse to fine, of equal length >= 1.
   */
  ErrorEstimate
  estimate_error(const std::vector<double> &values,
                 const std::vector<double> &n_dofs,
                 const unsigned int         dim,
                 const double               formal_order);
} // namespace knee_contact

#endif
