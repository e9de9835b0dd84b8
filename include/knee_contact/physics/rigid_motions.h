#ifndef knee_contact_rigid_motions_h
#define knee_contact_rigid_motions_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/tria.h>

#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Bodies placed by a rigid motion per load case (Load cases/Motion i):
   * the femoral component flexed, the tibial side translated and rotated
   * along a gait cycle (ISO 14243-3), a block dragged over a base. Linear
   * elasticity takes a small rotation only, so the motion is not a
   * displacement: each case's mesh is the scene's with the moved bodies'
   * vertices placed at the case's pose
   *   P_t(X) = c + R(theta(t)) (X - c) + d(t),
   * the contact pairs are found again there, and the case solves for the
   * elastic displacement from that pose. A frictional pair's slip in a case
   * counts the rigid motion of its slave point against the master point it
   * now faces (relative_motion()) besides the elastic displacements.
   */
  template <int dim>
  class RigidMotions
  {
  public:
    /** No motion moves a material id: the value motion_of() gives. */
    static constexpr unsigned int none = std::numeric_limits<unsigned>::max();

    /**
     * Declare "Load cases/Number of motions" and @p n_subsections
     * subsections "Motion i", each entry bound to the member it sets.
     */
    void
    add_parameters(ParameterHandler &prm, const unsigned int n_subsections);

    /** How many motions the scene declares (read before the subsections). */
    unsigned int n_motions = 0;

    /**
     * After parsing: the expressions, ids and axes, and each motion's pose
     * at every load parameter of @p t (finite), so that a run does not stop
     * at a late case.
     */
    void
    check_parameters(const std::vector<double> &t);

    bool
    empty() const
    {
      return motions.empty();
    }

    /**
     * Every moved material id is in the mesh, and no vertex is shared by
     * cells of two motions (or of a moved and a fixed cell): a body moves
     * whole. The error names the motion and the ids.
     */
    void
    check_mesh(const Triangulation<dim> &triangulation) const;

    /** The motion that moves material @p id, or none. */
    unsigned int
    motion_of(const types::material_id id) const;

    /**
     * Place each moved body's vertices from the pose at @p t_from to that at
     * @p t_to (t_from NaN: the mesh is the scene's, unmoved). Refuses, naming
     * the parameter and t, an angle or translation that is not finite.
     */
    void
    move(Triangulation<dim> &triangulation,
         const double        t_from,
         const double        t_to) const;

    /**
     * The rotation from the pose at @p t_from to that at @p t_to of motion
     * @p motion (identity for none): R(theta(t_to)) R(theta(t_from))^T.
     */
    Tensor<2, dim>
    rotation_change(const unsigned int motion,
                    const double       t_from,
                    const double       t_to) const;

    /**
     * Turn the displacement vectors of the moved bodies' vertices of @p u
     * (a field on @p dof_handler, FE_Q(1)^dim or P1^dim) from the pose at
     * @p t_from to that at @p t_to: the previous case's displacements seen
     * in this case's frame.
     */
    void
    rotate_displacements(const DoFHandler<dim> &dof_handler,
                         const double           t_from,
                         const double           t_to,
                         Vector<double>        &u) const;

    /**
     * The motion of each dof's vertex (none for fixed bodies), on
     * @p dof_handler.
     */
    std::vector<unsigned int>
    motion_of_dofs(const DoFHandler<dim> &dof_handler) const;

    /**
     * The rigid slip since the pose at @p t_from of the point now at @p x
     * on a body of motion @p slave over the point of a body of motion
     * @p master now at x: how far each moved, the slave's less the
     * master's, (x - P^s_from((P^s_to)^-1 x)) - (x - P^m_from((P^m_to)^-1
     * x)) = P^m_from((P^m_to)^-1 x) - P^s_from((P^s_to)^-1 x).
     */
    Tensor<1, dim>
    relative_motion(const unsigned int slave,
                    const unsigned int master,
                    const Point<dim>  &x,
                    const double       t_from,
                    const double       t_to) const;

  private:
    struct Entry
    {
      std::vector<unsigned int> ids;
      std::string               axis        = "0; 0; 1";
      std::string               centre      = dim == 2 ? "0; 0" : "0; 0; 0";
      std::string               angle       = "0";
      std::string               translation = dim == 2 ? "0; 0" : "0; 0; 0";
    };
    std::vector<Entry> entries;

    struct Motion
    {
      std::string                          name;
      std::vector<types::material_id>      ids;
      Tensor<1, 3>                         axis;
      Point<dim>                           centre;
      std::unique_ptr<FunctionParser<dim>> angle;
      std::unique_ptr<FunctionParser<dim>> translation;
    };
    std::vector<Motion> motions;

    /** R(theta(t)) and d(t) of motion @p m, checked finite. */
    std::pair<Tensor<2, dim>, Tensor<1, dim>>
    pose(const unsigned int m, const double t) const;

    /** P_t_to(P_t_from^-1(x)) for motion @p m (x itself for none). */
    Point<dim>
    transfer(const unsigned int m,
             const Point<dim>  &x,
             const double       t_from,
             const double       t_to) const;
  };
} // namespace knee_contact

#endif
