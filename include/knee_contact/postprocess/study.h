#ifndef knee_contact_study_h
#define knee_contact_study_h

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
    /** The contact solver's path and figures (summary.json's "solver"). */
    std::string                   solver;
    std::map<std::string, double> solver_figures;
  };

  /**
   * The cycles of one sequence as a deal.II ConvergenceTable with the
   * observed rates (h ~ n_dofs^(-1/dimension)) of every error the scene has a
   * reference for; wall times only if @p with_times (not in test output).
   */
  void
  print_convergence_table(const std::vector<CycleRecord> &records,
                          const unsigned int              dimension,
                          const bool                      with_times,
                          std::ostream                   &out);

  /**
   * All records as CSV, one row per cycle, with the contact solver's path,
   * contact solve, reference solve (if measured) and contact unknowns.
   */
  void
  write_study_csv(const std::vector<CycleRecord> &records, std::ostream &out);
} // namespace knee_contact

#endif
