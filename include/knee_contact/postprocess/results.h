#ifndef knee_contact_results_h
#define knee_contact_results_h

#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/materials.h>
#include <knee_contact/postprocess/problem_access.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  template <int dim>
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
    Tensor<1, dim> force_on_slave;
    double         max_pressure = 0;
    /**
     * Length (2D) or area (3D) of slave boundary in contact, sum of the
     * active shares [m or m^2].
     */
    double contact_length = 0;
    /** Where the peak pressure is: its slave vertex. */
    Point<dim> peak_location;
    /**
     * The centre of pressure: the slave vertices weighted by their contact
     * forces, sum lambda_p x_p / sum lambda_p (the origin without force).
     */
    Point<dim> centre_of_pressure;
    /** force / contact_length [Pa] (0 without contact). */
    double mean_pressure = 0;
    /**
     * With friction (on any interface: friction is true and the figures
     * are those of every interface): the tangential force on the slave body,
     * -sum lambda_t,p t_p [N/m], the pairs that stick and slip and their shares
     * of the slave side [m], the largest slip of this load case and the largest
     * accumulated along the load path [m].
     */
    bool           friction = false;
    Tensor<1, dim> tangential_force_on_slave;
    unsigned int   n_stick              = 0;
    unsigned int   n_slip               = 0;
    double         stick_length         = 0;
    double         slip_length          = 0;
    double         max_slip             = 0;
    double         max_accumulated_slip = 0;
  };

  /**
   * The derived quantities of a solution: reactions, loads, equilibrium,
   * stress ranges and contact results. Forces are per unit thickness
   * [N/m] in 2D and [N] in 3D, energies [J/m] and [J].
   */
  template <int dim>
  struct Results
  {
    unsigned int n_dofs  = 0;
    unsigned int n_cells = 0;
    // The elements solved with: "Q1" or "P1".
    std::string  elements;
    unsigned int n_bodies = 0;
    /** Reaction force per Gamma_u/Gamma_o boundary id [N/m]. */
    std::map<types::boundary_id, Tensor<1, dim>> reactions;
    /** Total applied load: tractions plus body forces [N/m]. */
    Tensor<1, dim> applied_load;
    /** |load + reactions| / max(|load|, sum |reactions|). */
    double equilibrium_residual = 0;
    /** a(u, u) [J/m]. */
    double energy           = 0;
    double max_displacement = 0;
    /** The vertices of each cell (a mesh has one kind of cell). */
    unsigned int n_cell_vertices = 0;
    /**
     * tau_yy [Pa] at the vertices of each active cell, n_cell_vertices a
     * cell (by active_cell_index(), deal.II's vertex order): what the 2D
     * pictures show. Stored for the cell's own vertices (a tetrahedron's
     * 4, not a hexahedron's 8).
     */
    std::vector<double> vertex_stress_yy;
    /** Von Mises stress [Pa] in the same places: the 3D pictures. */
    std::vector<double> vertex_von_mises;

    /** tau_yy at vertex @p v of cell @p cell. */
    double
    stress_yy_at(const unsigned int cell, const unsigned int v) const
    {
      return vertex_stress_yy[vertex_entry(cell, v)];
    }
    /** Von Mises stress at vertex @p v of cell @p cell (as stress_yy_at). */
    double
    von_mises_at(const unsigned int cell, const unsigned int v) const
    {
      return vertex_von_mises[vertex_entry(cell, v)];
    }
    /** The index of vertex @p v of cell @p cell in the two fields. */
    std::size_t
    vertex_entry(const unsigned int cell, const unsigned int v) const
    {
      AssertIndexRange(v, n_cell_vertices);
      return std::size_t(cell) * n_cell_vertices + v;
    }
    /** min and max tau_yy per material id [Pa], at cell vertices. */
    std::map<types::material_id, std::pair<double, double>> stress_yy_range;
    /** max von Mises stress per material id [Pa], at cell vertices. */
    std::map<types::material_id, double> von_mises_max;
    std::vector<InterfaceResult<dim>>    interfaces;
    /** Contact pressure lambda_p / length_p per pair [Pa]. */
    std::vector<double> pressure;
  };

  template <int dim>
  Results<dim>
  compute_results(const ProblemAccess<dim> &state);
} // namespace knee_contact

#endif
