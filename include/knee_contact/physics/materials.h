#ifndef knee_contact_materials_h
#define knee_contact_materials_h

#include <knee_contact/mesh/mesh_readers.h>

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/grid/tria.h>

#include <map>
#include <memory>
#include <set>
#include <string>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Isotropic linear elastic material of one material id: Hooke's law
   * tau_ij = c_ijkl e_kl, the seed's eq. (2); in 2D in plane strain or plane
   * stress.
   */
  template <int dim>
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
    bool                                 reduced_volumetric = false;
    std::unique_ptr<FunctionParser<dim>> body_force;
    /** The body force is written as zeros: nothing to integrate. */
    bool body_force_is_zero = false;
    /** The body force is written as numbers: the same everywhere. */
    bool body_force_is_constant = false;

    /**
     * Stress from strain (in 2D the in-plane components).
     */
    SymmetricTensor<2, dim>
    stress(const SymmetricTensor<2, dim> &strain) const;

    /**
     * 2D: the out-of-plane stress tau_zz, nu (tau_xx + tau_yy) in plane
     * strain, zero in plane stress. 3D: tau_zz itself.
     */
    double
    stress_zz(const SymmetricTensor<2, dim> &stress) const;

    /**
     * Von Mises stress (in 2D including tau_zz).
     */
    double
    von_mises(const SymmetricTensor<2, dim> &stress) const;
  };



  /**
   * The table of materials by material id, read from the subsection
   * "Materials" of the scene file.
   */
  template <int dim>
  class Materials
  {
  public:
    /**
     * Declare the subsection "Materials" with the subsections 'Material 0'
     * ... 'Material @p n_materials - 1', each entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm, const unsigned int n_materials);

    /**
     * After parsing: the table from the entries, with the checks the
     * patterns cannot make (ids and names unique, E and nu in range, the
     * contrast of the moduli, the body forces' expressions). With Elastic
     * constants = mesh file, E and nu of each material come from
     * @p deck_materials (by material id); a material that also gives them
     * must agree.
     */
    void
    check_parameters(
      const std::map<types::material_id, mesh_readers::DeckMaterial>
        &deck_materials = {});

    /** Elastic constants = mesh file: E and nu come from the Abaqus deck. */
    bool constants_from_mesh = false;

    /** 'Number of materials' as the scene gives it. */
    unsigned int n_materials = 1;

    /**
     * Throw if a cell of @p triangulation has a material id without a
     * material.
     */
    void
    check_mesh(const Triangulation<dim> &triangulation) const;

    const Material<dim> &
    operator[](const types::material_id id) const;

    /**
     * The largest Young's modulus, the stiffness scale of the scene.
     */
    double
    max_youngs_modulus() const;

    double
    min_youngs_modulus() const;

    /** The material ids the scene gives a material. */
    std::set<types::material_id>
    ids() const
    {
      std::set<types::material_id> result;
      for (const auto &[id, material] : materials)
        result.insert(id);
      return result;
    }

    /**
     * Evaluate the body forces at load parameter @p t from now on.
     */
    void
    set_load_parameter(const double t);

  private:
    /** One 'Material k' subsection as the scene wrote it. */
    struct Entry
    {
      unsigned int material_id = 1;
      std::string  name;
      double       youngs_modulus = 1e9;
      double       poissons_ratio = 0.3;
      // Whether the scene file sets them (else the defaults above).
      bool        youngs_modulus_given = false, poissons_ratio_given = false;
      bool        reduced_volumetric = false;
      std::string body_force         = dim == 2 ? "0; 0" : "0; 0; 0";
    };
    std::vector<Entry> entries;

    /**
     * E and nu of material id @p id (Materials/@p section) from the deck,
     * refused if the deck gives none or the scene gives others.
     */
    void
    take_deck_constants(
      const Entry             &entry,
      const std::string       &section,
      const types::material_id id,
      const std::map<types::material_id, mesh_readers::DeckMaterial>
                    &deck_materials,
      Material<dim> &material);
    bool plane_strain = true;

    std::map<types::material_id, Material<dim>> materials;
  };
} // namespace knee_contact

#endif
