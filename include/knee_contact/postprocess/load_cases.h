#ifndef knee_contact_load_cases_h
#define knee_contact_load_cases_h

#include <knee_contact/postprocess/results.h>

#include <deal.II/base/parameter_handler.h>

#include <limits>
#include <ostream>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * A sequence of loads on one geometry (a knee over a gait cycle, a load
   * sweep): the scene's tractions, pressures and body forces are
   * expressions of the load parameter t, and each value of t is a load
   * case. The mesh, the constraints and the factorisation are those of the
   * first case; each further case assembles only its load vector and runs
   * the active-set loop from the previous case's active set
   * (ContactSystem::set_rhs()). Where Load cases/Motion moves bodies
   * (RigidMotions) each case is set up anew at its pose instead
   * (ContactProblem::move_to_case()).
   */
  class LoadCases
  {
  public:
    /**
     * Declare the subsection "Load cases", its entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /** After parsing: the values of t from the entries and ranges. */
    void
    check_parameters();

    /**
     * The values of t in the order given; {0} if the scene gives none.
     */
    const std::vector<double> &
    values() const
    {
      return t;
    }

    /**
     * The figures of one case, for the table.
     */
    template <int dim>
    struct Record
    {
      double       t            = 0;
      unsigned int n_iterations = 0;
      bool         converged    = true;
      /** Wall time of the case's solve [s]: load vector to displacement. */
      double       solve_time = 0;
      Results<dim> results;
      /**
       * The energy's error bar [J/m in 2D, J in 3D]: strain recovery on the
       * case's mesh (recovered_energy_estimate()); NaN without one.
       */
      double energy_error = std::numeric_limits<double>::quiet_NaN();
      /** The largest peak pressure's error bar [Pa]; NaN without one. */
      double peak_pressure_error = std::numeric_limits<double>::quiet_NaN();
    };

    /**
     * The table load_cases.csv: per case t, iterations, energy, max |u|,
     * applied load, the reaction of every Gamma_u/Gamma_o boundary id, and
     * per interface active pairs, force, peak pressure and contact length.
     */
    template <int dim>
    static void
    write_csv(const std::vector<Record<dim>> &records, std::ostream &out);

    /**
     * The same table, shorter, on the terminal; the solve times only if
     * @p with_times (test output must not depend on the machine).
     */
    template <int dim>
    static void
    print_table(const std::vector<Record<dim>> &records,
                const bool                      with_times,
                std::ostream                   &out);

    /**
     * The case's folder name: case_000, case_001, ...
     */
    static std::string
    folder(const unsigned int index);

  private:
    /** 'Values of t' as the scene wrote it: numbers and ranges. */
    std::vector<std::string> entries;
    std::vector<double>      t = {0.};
  };
} // namespace knee_contact

#endif
