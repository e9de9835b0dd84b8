#ifndef knee_contact_verification_h
#define knee_contact_verification_h

#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/materials.h>
#include <knee_contact/postprocess/results.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <memory>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Errors of one solution against the references a scene states.
   * NaN where the scene gives no reference.
   */
  struct Errors
  {
    double l2_relative       = std::numeric_limits<double>::quiet_NaN();
    double energy_relative   = std::numeric_limits<double>::quiet_NaN();
    double nodal_relative    = std::numeric_limits<double>::quiet_NaN();
    double stress_relative   = std::numeric_limits<double>::quiet_NaN();
    double pressure_relative = std::numeric_limits<double>::quiet_NaN();
    /** sqrt(sum l_p (p_h - p)^2 / sum l_p p^2) over the slave vertices. */
    double pressure_l2_relative   = std::numeric_limits<double>::quiet_NaN();
    double peak_pressure_relative = std::numeric_limits<double>::quiet_NaN();
    double contact_length_error   = std::numeric_limits<double>::quiet_NaN();
    /** |a(u,u) - reference| / reference. */
    double energy_reference_relative = std::numeric_limits<double>::quiet_NaN();
    /** Relative error of the extreme tau_yy in the reference material. */
    double stress_extreme_relative = std::numeric_limits<double>::quiet_NaN();

    /**
     * The error a speed-against-error study ranks by: the peak pressure
     * error if the scene gives a reference, else the energy error.
     */
    double
    primary() const;
  };



  /**
   * Checks of a solution against independent references stated in the
   * scene's "Verification" subsection (exact fields, analytic values), and
   * the KKT conditions of the contact problem. Each check prints one line
   * "check <what>: <value> <= <tolerance>: PASS|FAIL".
   */
  template <int dim>
  class Verification
  {
  public:
    /**
     * Declare the subsection "Verification", each entry bound to the member
     * it sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /** After parsing: the expressions and constants of the entries. */
    void
    check_parameters();

    Errors
    compute_errors(const DoFHandler<dim>   &dof_handler,
                   const Vector<double>    &solution,
                   const Materials<dim>    &materials,
                   const ContactPairs<dim> &pairs,
                   const Results<dim>      &results) const;

    /**
     * The checks of a study (Refinement/Strategy = compare) on its two
     * sequences: the primary error of the uniform sequence decreases over
     * its last three cycles, and the adaptive sequence reaches the finest
     * uniform error with fewer dofs. Returns the number that failed.
     */
    unsigned int
    check_study(const std::vector<Errors> &uniform_errors,
                const std::vector<double> &uniform_dofs,
                const std::vector<Errors> &adaptive_errors,
                const std::vector<double> &adaptive_dofs,
                std::ostream              &out) const;

    /**
     * Print the checks of the final cycle and of the convergence rates;
     * return the number that failed.
     */
    unsigned int
    check(const Results<dim>        &results,
          const ContactSolution     &contact,
          const bool                 has_contact,
          const std::vector<Errors> &errors,
          const std::vector<double> &n_dofs,
          std::ostream              &out) const;


    /**
     * Evaluate the exact solutions at load parameter @p t from now on (they
     * may depend on t like the loads).
     */
    void
    set_load_parameter(const double t);

  private:
    /** The expressions as the scene wrote them. */
    struct Entries
    {
      std::string exact_displacement, exact_stress, exact_pressure;
      std::string peak_pressure, contact_length, reference_energy;
      std::vector<std::pair<std::string, std::string>> extreme_stress;
      std::vector<std::pair<std::string, std::string>> interface_forces;
      std::vector<std::pair<std::string, std::string>> tangential_forces;
    } entries;

    std::unique_ptr<FunctionParser<dim>>        exact_displacement;
    std::unique_ptr<FunctionParser<dim>>        exact_stress;
    std::unique_ptr<FunctionParser<dim>>        exact_pressure;
    double                                      tolerance         = 1e-10;
    double                                      min_l2_rate       = 0;
    double                                      min_energy_rate   = 0;
    double                                      min_pressure_rate = 0;
    double                                      max_l2_error      = 0;
    bool                                        check_kkt         = true;
    double                                      peak_pressure     = 0;
    double                                      peak_tolerance    = 0.03;
    double                                      contact_length    = 0;
    double                                      length_tolerance  = 0;
    double                                      reference_energy  = 0;
    double                                      energy_tolerance  = 1e-3;
    double                                      extreme_stress_tolerance = 0.05;
    std::string                                 extreme_stress_material;
    double                                      extreme_stress = 0;
    std::vector<std::pair<std::string, double>> interface_forces;
    std::vector<std::pair<std::string, double>> tangential_forces;
    double                                      force_tolerance = 1e-8;
  };
} // namespace knee_contact

#endif
