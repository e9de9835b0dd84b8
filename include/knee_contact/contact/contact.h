#ifndef knee_contact_contact_h
#define knee_contact_contact_h

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_handler.h>

#include <string>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * One contact pair of the seed's Gamma_c: a vertex x_p of the slave side
   * and the point y_p where the slave's outward normal n_p meets the master
   * side. It is one row of the seed's constraint A x <= 0 (its eq. (13)),
   * here with the initial gap:
   *   n_p . (u^k(x_p) - u^l(y_p)) <= g_p,   g_p = n_p . (y_p - x_p),
   * where u^l(y_p) interpolates the master face linearly. Matching meshes
   * give y_p at a master vertex: the seed's node pairs.
   */
  struct ContactPair
  {
    unsigned int interface = 0;
    Point<2>     position;
    Point<2>     master_point;
    Tensor<1, 2> normal;
    double       gap = 0;
    /** The slave vertex's share of the slave boundary length [m]. */
    double length = 0;
    /** Dof indices of the slave vertex (x, y). */
    std::array<types::global_dof_index, 2> slave_dofs;

    /** The row a_p: (dof, coefficient). */
    std::vector<std::pair<types::global_dof_index, double>> row;
    /**
     * The row with the Gamma_u and Gamma_o constraints substituted, over
     * dofs those leave free, and its right hand side.
     */
    std::vector<std::pair<types::global_dof_index, double>> reduced_row;
    double                                                  reduced_gap = 0;
    /**
     * The dof an active pair eliminates (a free slave component if there is
     * one, else a free master component); invalid if the row has no free
     * dof left, i.e. Gamma_u or Gamma_o already decide it.
     */
    types::global_dof_index eliminated       = numbers::invalid_dof_index;
    bool                    slave_eliminated = true;

    /** a_p . x */
    double
    jump(const Vector<double> &x) const;
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



  struct ContactInterface
  {
    std::string        name;
    types::boundary_id slave_id    = 0;
    types::boundary_id master_id   = 0;
    Pairing            pairing     = Pairing::mortar;
    double             maximum_gap = 0;
  };



  /**
   * The contact interfaces of a scene and their pairing. No library pairs
   * nodes across bodies for this formulation, so it is written here.
   */
  class ContactInterfaces
  {
  public:
    static void
    declare_parameters(ParameterHandler &prm, const unsigned int n_interfaces);

    void
    parse_parameters(ParameterHandler &prm, const unsigned int n_interfaces);

    /**
     * Throw if a side's boundary id is missing, or both sides of an
     * interface lie on the same body.
     */
    void
    check_mesh(const Triangulation<2>          &triangulation,
               const std::vector<unsigned int> &body_ids) const;

    /**
     * Pair every slave vertex of every interface (see ContactPair), and
     * choose each pair's eliminated dof given the Gamma_u/Gamma_o
     * @p constraints (closed).
     */
    std::vector<ContactPair>
    make_pairs(const DoFHandler<2>             &dof_handler,
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
