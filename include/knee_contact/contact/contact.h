#ifndef knee_contact_contact_h
#define knee_contact_contact_h

#include <knee_contact/solver/contact_row.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_handler.h>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Where a contact row sits: the slave vertex x_p and the unit normal n_p
   * of its row a_p x <= g_p (ContactRow), for output and refinement; the
   * solver never sees it. Node-to-segment rows read
   *   n_p . (u^k(x_p) - u^l(y_p)) <= g_p,   g_p = n_p . (y_p - x_p),
   * with y_p where n_p meets the master side (matching meshes: a master
   * vertex, the seed's node pairs); mortar rows weigh the master side's
   * displacement over the slave vertex's support instead.
   */
  template <int dim>
  struct ContactPoint
  {
    Point<dim>     position;
    Tensor<1, dim> normal;
    /** Dof indices of the slave vertex (x, y[, z]). */
    std::array<types::global_dof_index, dim> slave_dofs;
    /**
     * With friction (2D): the unit tangent of the pair's tangential row,
     * that of the common normal n - n_master (n_master: the master face
     * the slave normal meets), t = (-m_y, m_x) for m the common normal.
     * On curved sides both normals tilt over the contact zone; the slave's
     * alone would count part of the normal approach as slip.
     */
    Tensor<1, dim> tangent;
  };



  /**
   * The combinations a N + b T of a pair's normal and tangential rows
   * whose slave parts (n and t) are e_x and e_y: {{a_x, b_x}, {a_y, b_y}},
   * the inverse of the matrix with columns n and t. A sticking pair is
   * held by these two rows; their multipliers l_x, l_y are
   * lambda_n = l_x a_x + l_y a_y and lambda_t = l_x b_x + l_y b_y.
   */
  inline std::array<std::array<double, 2>, 2>
  stick_coefficients(const Tensor<1, 2> &n, const Tensor<1, 2> &t)
  {
    const double det = n[0] * t[1] - n[1] * t[0];
    return {{{{t[1] / det, -n[1] / det}}, {{-t[0] / det, n[0] / det}}}};
  }



  /**
   * The contact rows of a mesh and, index by index, their points.
   */
  template <int dim>
  struct ContactPairs
  {
    std::vector<ContactRow>        rows;
    std::vector<ContactPoint<dim>> points;
    /**
     * With friction on any interface: for each row p the tangential row
     * t_p . (u_slave - u_master) [rows[p]'s weights, the tangent
     * points[p].tangent in place of n], gap 0 (loaded in one step; along
     * a load path the last case's jump); empty if no interface has
     * friction.
     */
    std::vector<ContactRow> tangential;
    /**
     * With friction: the rows that hold a sticking pair, the combinations
     * of N and T whose slave parts are e_x and e_y (see make_pairs).
     */
    std::vector<ContactRow> stick_x, stick_y;

    /**
     * The rows the solver sees: the normal rows, then the tangential, then
     * stick_x and stick_y.
     */
    std::vector<ContactRow>
    solver_rows() const
    {
      std::vector<ContactRow> all = rows;
      for (const auto *more : {&tangential, &stick_x, &stick_y})
        all.insert(all.end(), more->begin(), more->end());
      return all;
    }

    std::size_t
    size() const
    {
      return rows.size();
    }

    bool
    empty() const
    {
      return rows.empty();
    }

    void
    push_back(ContactRow &&row, const ContactPoint<dim> &point)
    {
      rows.push_back(std::move(row));
      points.push_back(point);
    }
  };



  /**
   * The contact CSV of an interface: contact_<name>.csv with every
   * character but letters, digits and '-' replaced by '_'.
   */
  std::string
  csv_file_name(const std::string &interface_name);



  /**
   * How an interface's contact conditions are discretised (the seam: each
   * has its row builder in contact_sides.h).
   */
  enum class Pairing
  {
    mortar,
    node_to_segment,
    node_to_node
  };

  /** The name of a Pairing as in the scene files. */
  std::string
  pairing_name(const Pairing pairing);



  /** The friction law of an interface. */
  enum class Friction
  {
    none,
    tresca,
    coulomb
  };

  struct ContactInterface
  {
    std::string        name;
    types::boundary_id slave_id    = 0;
    types::boundary_id master_id   = 0;
    Pairing            pairing     = Pairing::mortar;
    double             maximum_gap = 0;
    Friction           friction    = Friction::none;
    /** Coulomb: |tau_t| <= mu p. */
    double friction_coefficient = 0;
    /** Tresca: |tau_t| <= this bound [Pa]. */
    double tresca_bound = 0;
  };



  /**
   * The contact interfaces of a scene and their pairing. No library pairs
   * nodes across bodies for this formulation, so it is written here.
   */
  class ContactInterfaces
  {
  public:
    /**
     * Declare the subsection "Contact" with the subsections 'Interface 0'
     * ... 'Interface @p n_interfaces - 1', each entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm, const unsigned int n_interfaces);

    /**
     * After parsing: the checks the patterns cannot make (names valid and
     * distinct as file names, two sides, no boundary id in two
     * interfaces).
     */
    void
    check_parameters() const;

    /**
     * Throw if an interface asks for what the mesh's dimension @p dim
     * lacks: friction in 3D.
     */
    void
    check_dimension(const unsigned int dim) const;

    /** 'Number of interfaces' as the scene gives it. */
    unsigned int n_interfaces = 0;

    /**
     * Throw if a side's boundary id is missing, or both sides of an
     * interface lie on the same body.
     */
    template <int dim>
    void
    check_mesh(const Triangulation<dim>        &triangulation,
               const std::vector<unsigned int> &body_ids) const;

    /**
     * Pair every slave vertex of every interface (see ContactPoint), and
     * choose each row's eliminated dof given the Gamma_u/Gamma_o
     * @p constraints (closed). 2D and 3D; friction rows in 2D only (3D
     * friction is refused by check_dimension()).
     */
    template <int dim>
    ContactPairs<dim>
    make_pairs(const DoFHandler<dim>           &dof_handler,
               const AffineConstraints<double> &constraints) const;

    const std::vector<ContactInterface> &
    interfaces() const
    {
      return list;
    }

  private:
    std::vector<ContactInterface> list;
  };

} // namespace knee_contact

#endif
