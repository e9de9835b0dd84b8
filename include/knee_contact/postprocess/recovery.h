#ifndef knee_contact_recovery_h
#define knee_contact_recovery_h

#include <knee_contact/physics/materials.h>

#include <deal.II/base/symmetric_tensor.h>
#include <deal.II/base/tensor.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * A traction a recovered stress must have at a surface vertex: sigma n =
   * -pressure n (frictionless contact: no tangential part), for the vertex
   * whose first displacement dof is @p dof.
   */
  template <int dim>
  struct SurfaceTraction
  {
    types::global_dof_index dof = 0;
    Tensor<1, dim>          normal;
    double                  pressure = 0;
  };



  /**
   * Strain recovery of two displacements u and z on one mesh. Each strain
   * is averaged at each vertex over the cells of one material that share
   * it (so that a bonded material junction, where the strain jumps, is not
   * smoothed over); at a contact vertex given a SurfaceTraction (see
   * RecoveredStrain) the average's normal stress is replaced by the known
   * contact traction (sigma* n = -p n: the recovered stress satisfies the
   * boundary condition the discrete multiplier gives); the averages are
   * interpolated by the cells' own linear shape functions. With e_u =
   * e*(u_h) - e(u_h) and e_z likewise, per cell K:
   *   product_K = integral over K of e_z : C : e_u   (estimates a(u - u_h,
   *               z - z_h) on K),
   *   eta_u,K^2 = integral over K of e_u : C : e_u.
   * With z the influence (dual) solution of a quantity J, the sum of
   * product_K estimates the error J(u) - J(u_h) (goal-oriented error
   * estimation by recovery; the error representation of Becker and
   * Rannacher, Acta Numerica 2001, with the recovered strains in place of
   * the exact ones), and |product_K| indicates where to refine for J.
   *
   * Written here because deal.II's estimators (Kelly) give indicators with
   * an unknown constant, not an error in the quantity's units, and no
   * library the project uses recovers strains or weights them by a dual.
   */
  struct RecoveredProduct
  {
    /** Sum over cells of product_K. */
    double product = 0;
    /** Sum over cells of eta_u,K^2. */
    double eta_u_squared = 0;
    /** |product_K| by active cell index (if asked for). */
    Vector<float> indicators;
  };

  /**
   * The recovered strain of one displacement at each (vertex, material):
   * the average described above, with the contact tractions of
   * @p tractions imposed. Stored by vertex index (a vertex has one entry
   * per material that meets there), so that one recovery serves several
   * products.
   */
  template <int dim>
  class RecoveredStrain
  {
  public:
    RecoveredStrain(const DoFHandler<dim>                   &dof_handler,
                    const Vector<double>                    &solution,
                    const Materials<dim>                    &materials,
                    const std::vector<SurfaceTraction<dim>> &tractions = {});

    /**
     * The recoveries of several displacements in one pass over the cells:
     * entry i of @p solutions with the tractions @p tractions[i].
     */
    static std::vector<RecoveredStrain<dim>>
    of(const DoFHandler<dim>                                &dof_handler,
       const std::vector<const Vector<double> *>            &solutions,
       const Materials<dim>                                 &materials,
       const std::vector<std::vector<SurfaceTraction<dim>>> &tractions);

    /** The recovered strain at @p vertex in @p material. */
    const SymmetricTensor<2, dim> &
    operator()(const unsigned int       vertex,
               const types::material_id material) const;

  private:
    RecoveredStrain() = default;

    /** Imposes @p tractions on the averages (see the class). */
    void
    impose(const std::vector<SurfaceTraction<dim>> &tractions,
           const std::vector<unsigned int>         &vertex_of_dof,
           const Materials<dim>                    &materials);

    std::vector<
      std::vector<std::pair<types::material_id, SymmetricTensor<2, dim>>>>
      averages;
  };

  /** An influence (dual) solution z and its recovery. */
  template <int dim>
  struct Influence
  {
    const Vector<double>       *z         = nullptr;
    const RecoveredStrain<dim> *recovered = nullptr;
  };

  /**
   * The products above of u with each of @p influences in one pass over
   * the cells (u's recovered strain error computed once per point); each
   * entry has the same eta_u_squared.
   */
  template <int dim>
  std::vector<RecoveredProduct>
  recovered_error_products(const DoFHandler<dim>             &dof_handler,
                           const Vector<double>              &u,
                           const RecoveredStrain<dim>        &recovered_u,
                           const std::vector<Influence<dim>> &influences,
                           const Materials<dim>              &materials,
                           const bool with_indicators = false);

} // namespace knee_contact

#endif
