#ifndef knee_contact_materials_h
#define knee_contact_materials_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/grid/tria.h>

#include <map>
#include <memory>
#include <string>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Isotropic linear elastic material of one material id: Hooke's law
   * tau_ij = c_ijkl e_kl, the seed's eq. (2), in plane strain or plane stress.
   */
  struct Material
  {
    std::string name;
    double      youngs_modulus = 0;
    double      poissons_ratio = 0;
    double      lambda         = 0;
    double      mu             = 0;
    bool        plane_strain   = true;
    /**
     * Selective reduced integration: the volumetric part lambda div u div v
     * with one Gauss point per cell, the standard remedy for the locking of
     * Q1 elements as nu approaches 1/2.
     */
    bool                               reduced_volumetric = false;
    std::unique_ptr<FunctionParser<2>> body_force;
    /** The body force is written as zeros: nothing to integrate. */
    bool body_force_is_zero = false;

    /**
     * In-plane stress from in-plane strain.
     */
    SymmetricTensor<2, 2>
    stress(const SymmetricTensor<2, 2> &strain) const;

    /**
     * The out-of-plane stress tau_zz: nu (tau_xx + tau_yy) in plane strain,
     * zero in plane stress.
     */
    double
    stress_zz(const SymmetricTensor<2, 2> &stress) const;

    /**
     * Von Mises stress including tau_zz.
     */
    double
    von_mises(const SymmetricTensor<2, 2> &stress) const;
  };



  /**
   * The table of materials by material id, read from the subsection
   * "Materials" of the scene file.
   */
  class Materials
  {
  public:
    static void
    declare_parameters(ParameterHandler &prm, const unsigned int n_materials);

    void
    parse_parameters(ParameterHandler &prm, const unsigned int n_materials);

    /**
     * Throw if a cell of @p triangulation has a material id without a
     * material.
     */
    void
    check_mesh(const Triangulation<2> &triangulation) const;

    const Material &
    operator[](const types::material_id id) const;

    /**
     * The largest Young's modulus, the stiffness scale of the scene.
     */
    double
    max_youngs_modulus() const;

    double
    min_youngs_modulus() const;

    /**
     * Evaluate the body forces at load parameter @p t from now on.
     */
    void
    set_load_parameter(const double t);

  private:
    std::map<types::material_id, Material> materials;
  };
} // namespace knee_contact

#endif
