#ifndef knee_contact_results_h
#define knee_contact_results_h

#include <knee_contact/solver/active_set.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/materials.h>

#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <array>
#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  struct InterfaceResult
  {
    std::string name;
    /** The contact discretisation that produced the pressure. */
    Pairing      pairing  = Pairing::mortar;
    unsigned int n_pairs  = 0;
    unsigned int n_active = 0;
    /** Sum of lambda_p [N/m]: the normal contact force per unit thickness. */
    double force = 0;
    /** The force vector on the slave body, -sum lambda_p n_p [N/m]. */
    Tensor<1, 2> force_on_slave;
    double       max_pressure = 0;
    /** Length of slave boundary in contact, sum of the active shares [m]. */
    double contact_length = 0;
  };

  /**
   * The derived quantities of a solution: reactions, loads, equilibrium,
   * stress ranges and contact results.
   */
  struct Results
  {
    unsigned int n_dofs  = 0;
    unsigned int n_cells = 0;
    // The elements solved with: "Q1" or "P1".
    std::string  elements;
    unsigned int n_bodies = 0;
    /** Reaction force per Gamma_u/Gamma_o boundary id [N/m]. */
    std::map<types::boundary_id, Tensor<1, 2>> reactions;
    /** Total applied load: tractions plus body forces [N/m]. */
    Tensor<1, 2> applied_load;
    /** |load + reactions| / max(|load|, sum |reactions|). */
    double equilibrium_residual = 0;
    /** a(u, u) [J/m]. */
    double energy           = 0;
    double max_displacement = 0;
    /**
     * tau_yy [Pa] at the four vertices of each active cell (by
     * active_cell_index(), deal.II's vertex order): what the pictures show.
     */
    std::vector<std::array<double, 4>> vertex_stress_yy;
    /** min and max tau_yy per material id [Pa], at cell vertices. */
    std::map<types::material_id, std::pair<double, double>> stress_yy_range;
    std::vector<InterfaceResult>                            interfaces;
    /** Contact pressure lambda_p / length_p per pair [Pa]. */
    std::vector<double> pressure;
  };

  Results
  compute_results(const DoFHandler<2>             &dof_handler,
                  const std::vector<unsigned int> &body_of_cell,
                  const SparseMatrix<double>      &matrix,
                  const Vector<double>            &rhs,
                  const Vector<double>            &solution,
                  const Materials                 &materials,
                  const BoundaryConditions        &boundary_conditions,
                  const ContactInterfaces         &interfaces,
                  const std::vector<ContactPair>  &pairs,
                  const ContactSolution           &contact);
} // namespace knee_contact

#endif
