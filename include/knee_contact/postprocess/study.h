#ifndef knee_contact_study_h
#define knee_contact_study_h

#include <knee_contact/postprocess/error_estimate.h>
#include <knee_contact/postprocess/verification.h>

#include <map>
#include <ostream>
#include <string>
#include <vector>

namespace knee_contact
{
  /**
   * What one refinement cycle cost and how accurate it was: a row of the
   * speed-against-error study.
   */
  struct CycleRecord
  {
    std::string                   strategy;
    unsigned int                  cycle        = 0;
    unsigned int                  n_cells      = 0;
    unsigned int                  n_dofs       = 0;
    unsigned int                  n_pairs      = 0;
    unsigned int                  n_iterations = 0;
    std::map<std::string, double> wall_time; // per phase [s]
    double                        total_time    = 0;
    double                        peak_memory   = 0; // [MB], process so far
    double                        peak_pressure = 0;
    double                        energy        = 0;
    Errors                        errors;
    /** The reported quantities, by name, for the error estimates. */
    Quantities quantities;
    /**
     * The error bars of this cycle's peak pressure and energy from the
     * cycles so far, relative to the values (NaN: none): beside the true
     * errors, the estimates' effectivity.
     */
    double estimated_peak_pressure_error =
      std::numeric_limits<double>::quiet_NaN();
    double estimated_energy_error = std::numeric_limits<double>::quiet_NaN();
    /** eta^2 of the strain recovery (recovered_error_products()) on this mesh
     * [J/m, J]. */
    double recovered_energy_error = std::numeric_limits<double>::quiet_NaN();
    /** The contact solver's path and figures (summary.json's "solver"). */
    std::string                   solver;
    std::map<std::string, double> solver_figures;
  };

  /**
   * The cycles of one sequence as a deal.II ConvergenceTable with the
   * observed rates (h ~ n_dofs^(-1/dimension)) of every error the scene has a
   * reference for; wall times only if @p with_times, the estimated errors
   * of the peak pressure and the energy only if @p with_estimates (neither
   * in test output).
   */
  void
  print_convergence_table(const std::vector<CycleRecord> &records,
                          const unsigned int              dimension,
                          const bool                      with_times,
                          const bool                      with_estimates,
                          std::ostream                   &out);

  /**
   * All records as CSV, one row per cycle, with the contact solver's path,
   * contact solve, reference solve (if measured) and contact unknowns.
   */
  void
  write_study_csv(const std::vector<CycleRecord> &records, std::ostream &out);
} // namespace knee_contact

#endif
