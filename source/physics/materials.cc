#include <knee_contact/base/input.h>
#include <knee_contact/physics/materials.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>

namespace knee_contact
{
  template <int dim>
  SymmetricTensor<2, dim>
  Material<dim>::stress(const SymmetricTensor<2, dim> &strain) const
  {
    return lambda * trace(strain) * unit_symmetric_tensor<dim>() +
           2. * mu * strain;
  }



  template <int dim>
  double
  Material<dim>::stress_zz(const SymmetricTensor<2, dim> &stress) const
  {
    if constexpr (dim == 3)
      return stress[2][2];
    return plane_strain ? poissons_ratio * trace(stress) : 0.;
  }



  template <int dim>
  double
  Material<dim>::von_mises(const SymmetricTensor<2, dim> &s) const
  {
    // sqrt(3/2 s_dev : s_dev), written out as in the textbooks so that the
    // 2D case can add tau_zz.
    const double szz   = stress_zz(s);
    double       shear = s[0][1] * s[0][1];
    if constexpr (dim == 3)
      shear += s[1][2] * s[1][2] + s[0][2] * s[0][2];
    return std::sqrt(0.5 * ((s[0][0] - s[1][1]) * (s[0][0] - s[1][1]) +
                            (s[1][1] - szz) * (s[1][1] - szz) +
                            (szz - s[0][0]) * (szz - s[0][0])) +
                     3. * shear);
  }



  template <int dim>
  void
  Materials<dim>::add_parameters(ParameterHandler  &prm,
                                 const unsigned int n_subsections)
  {
    prm.enter_subsection("Materials");
    prm.add_parameter("Number of materials",
                      n_materials,
                      "How many subsections 'Material 0', 'Material 1', ... "
                      "follow.",
                      Patterns::Integer(1, 255));
    input::add_selection(prm,
                         "Plane",
                         plane_strain,
                         {{"strain", true}, {"stress", false}},
                         "2D model: plane strain (e_zz = 0, the default) or "
                         "plane stress (tau_zz = 0); unused in 3D.");
    input::add_selection(
      prm,
      "Elastic constants",
      constants_from_mesh,
      {{"scene", false}, {"mesh file", true}},
      "scene: each material's Young's modulus and Poisson's ratio as given "
      "below; mesh file: from the Abaqus deck of Mesh/File (the *Material "
      "of the *Solid Section of the material's cells, its isotropic "
      "*Elastic line); a material that gives them too must agree to 1e-9.");
    // Bound by reference: the vector is sized once, before binding.
    entries.clear();
    entries.resize(n_subsections);
    for (unsigned int m = 0; m < n_subsections; ++m)
      {
        Entry &entry      = entries[m];
        entry.material_id = m + 1;
        entry.name        = "material " + std::to_string(m + 1);
        prm.enter_subsection("Material " + std::to_string(m));
        prm.add_parameter("Material id",
                          entry.material_id,
                          "Material id of the cells (Gmsh: the tag of the "
                          "physical surface in 2D, physical volume in 3D).",
                          Patterns::Integer(0, 254));
        prm.add_parameter("Name", entry.name, "Name shown in results.");
        prm.add_parameter("Young's modulus",
                          entry.youngs_modulus,
                          "Young's modulus E [Pa], in [1e-20, 1e30].",
                          Patterns::Double());
        prm.add_parameter("Poisson's ratio",
                          entry.poissons_ratio,
                          "Poisson's ratio nu, in (-1, 0.5).",
                          Patterns::Double());
        // add_action runs once now with the default (deal.II 9.4), then
        // for the scene's value: the flags are reset below.
        prm.add_action("Young's modulus", [&entry](const std::string &) {
          entry.youngs_modulus_given = true;
        });
        prm.add_action("Poisson's ratio", [&entry](const std::string &) {
          entry.poissons_ratio_given = true;
        });
        input::add_selection(
          prm,
          "Volumetric integration",
          entry.reduced_volumetric,
          {{"full", false}, {"reduced", true}},
          "full: 2 Gauss points per direction for the whole stiffness; "
          "reduced: the volumetric part lambda div u div v with one point "
          "(selective reduced integration), against locking when nu is "
          "close to 0.5.");
        prm.add_parameter("Body force",
                          entry.body_force,
                          "Body force F = (F_x; F_y) [N/m^3] of the seed's "
                          "eq. (1), an expression in x, y [m]; in 3D (F_x; "
                          "F_y; F_z) in x, y, z.",
                          input::expression_pattern(3));
        prm.leave_subsection();
        entry.youngs_modulus_given = entry.poissons_ratio_given = false;
      }
    prm.leave_subsection();
  }



  template <int dim>
  void
  Materials<dim>::take_deck_constants(
    const Entry             &entry,
    const std::string       &section,
    const types::material_id id,
    const std::map<types::material_id, mesh_readers::DeckMaterial>
                  &deck_materials,
    Material<dim> &material)
  {
    const auto deck = deck_materials.find(id);
    AssertThrow(deck != deck_materials.end(),
                ExcMessage("Materials/" + section +
                           ": Elastic constants = mesh file, and no cell of "
                           "the deck has material id " +
                           std::to_string(id)));
    AssertThrow(deck->second.problem.empty(),
                ExcMessage("Materials/" + section +
                           ": Elastic constants = mesh file, and the deck "
                           "gives material id " +
                           std::to_string(id) +
                           " no constants: " + deck->second.problem));
    const auto agree = [&](const std::string &name,
                           const bool         given,
                           const double       scene,
                           const double       from_deck) {
      std::ostringstream text;
      text << std::setprecision(17) << "Materials/" << section << "/" << name
           << ": " << scene << " in the scene, " << from_deck
           << " in the deck's material '" << deck->second.name
           << "' (Elastic constants = mesh file: give it once, or the same)";
      AssertThrow(!given ||
                    std::abs(scene - from_deck) <= 1e-9 * std::abs(from_deck),
                  ExcMessage(text.str()));
      return from_deck;
    };
    material.youngs_modulus = agree("Young's modulus",
                                    entry.youngs_modulus_given,
                                    entry.youngs_modulus,
                                    deck->second.youngs_modulus);
    material.poissons_ratio = agree("Poisson's ratio",
                                    entry.poissons_ratio_given,
                                    entry.poissons_ratio,
                                    deck->second.poissons_ratio);
  }



  template <int dim>
  void
  Materials<dim>::check_parameters(
    const std::map<types::material_id, mesh_readers::DeckMaterial>
      &deck_materials)
  {
    for (unsigned int m = 0; m < entries.size(); ++m)
      {
        const Entry      &entry   = entries[m];
        const std::string section = "Material " + std::to_string(m);
        const auto id = static_cast<types::material_id>(entry.material_id);
        AssertThrow(materials.find(id) == materials.end(),
                    ExcMessage("Materials/" + section + ": material id " +
                               std::to_string(id) +
                               " is given to more than one material"));
        Material<dim> &material = materials[id];
        material.name           = entry.name;
        input::check_name(material.name, "Materials/" + section + "/Name");
        for (const auto &[other_id, other] : materials)
          AssertThrow(other_id == id || other.name != material.name,
                      ExcMessage("Materials/" + section + "/Name: '" +
                                 material.name +
                                 "' is the name of another material too"));
        material.youngs_modulus = entry.youngs_modulus;
        material.poissons_ratio = entry.poissons_ratio;
        if (constants_from_mesh)
          take_deck_constants(entry, section, id, deck_materials, material);
        material.plane_strain       = plane_strain;
        material.reduced_volumetric = entry.reduced_volumetric;
        const double       E        = material.youngs_modulus;
        const double       nu       = material.poissons_ratio;
        std::ostringstream E_text, nu_text;
        E_text << E;
        nu_text << nu;
        AssertThrow(std::isfinite(E) && E > 0,
                    ExcMessage("Materials/" + section +
                               "/Young's modulus: E must be > 0, got " +
                               E_text.str()));
        // Beyond these the stiffness or the displacement leaves the range
        // of double precision (E = 1e-300 gives an infinite energy).
        AssertThrow(E >= 1e-20 && E <= 1e30,
                    ExcMessage("Materials/" + section +
                               "/Young's modulus: E = " + E_text.str() +
                               " is outside [1e-20, 1e30] (choose units "
                               "that keep E and the loads near 1)"));
        AssertThrow(std::isfinite(nu) && nu > -1 && nu < 0.5,
                    ExcMessage("Materials/" + section +
                               "/Poisson's ratio: nu must lie in (-1, 0.5), "
                               "got " +
                               nu_text.str()));
        material.mu     = E / (2 * (1 + nu));
        material.lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
        if (dim == 2 && !plane_strain)
          material.lambda = 2 * material.lambda * material.mu /
                            (material.lambda + 2 * material.mu);
        material.body_force =
          input::parse_expression<dim>(entry.body_force,
                                       dim,
                                       "Materials/" + section + "/Body force",
                                       "",
                                       true);
        // Written as zeros ("0; 0", the 2D default): assembly skips it.
        material.body_force_is_zero = true;
        for (const auto &part : input::split(entry.body_force, ';'))
          material.body_force_is_zero &= input::number(part) == 0.;
        material.body_force_is_constant = input::numbers_only(entry.body_force);
      }

    // A contrast beyond 1e12 leaves fewer than 4 correct digits in the
    // soft body (round-off grows with the condition number).
    double E_min = std::numeric_limits<double>::max(), E_max = 0;
    for (const auto &[id, material] : materials)
      {
        E_min = std::min(E_min, material.youngs_modulus);
        E_max = std::max(E_max, material.youngs_modulus);
      }
    std::ostringstream contrast;
    contrast << std::setprecision(3) << E_max / E_min;
    AssertThrow(E_max <= 1e12 * E_min,
                ExcMessage("Materials: the contrast of Young's moduli " +
                           contrast.str() +
                           " exceeds 1e12; the soft body's displacements "
                           "would have no correct digits (model the stiff "
                           "body as rigid with a displacement condition)"));
  }



  template <int dim>
  void
  Materials<dim>::check_mesh(const Triangulation<dim> &triangulation) const
  {
    for (const auto &cell : triangulation.active_cell_iterators())
      AssertThrow(materials.find(cell->material_id()) != materials.end(),
                  ExcMessage(
                    "the mesh has cells with material id " +
                    std::to_string(cell->material_id()) +
                    " but no subsection of 'Materials' gives that id"));
  }



  template <int dim>
  const Material<dim> &
  Materials<dim>::operator[](const types::material_id id) const
  {
    const auto it = materials.find(id);
    Assert(it != materials.end(), ExcInternalError());
    return it->second;
  }



  template <int dim>
  double
  Materials<dim>::min_youngs_modulus() const
  {
    double E = std::numeric_limits<double>::max();
    for (const auto &m : materials)
      E = std::min(E, m.second.youngs_modulus);
    return E;
  }



  template <int dim>
  double
  Materials<dim>::max_youngs_modulus() const
  {
    double E = 0;
    for (const auto &m : materials)
      E = std::max(E, m.second.youngs_modulus);
    return E;
  }


  template <int dim>
  void
  Materials<dim>::set_load_parameter(const double t)
  {
    for (auto &m : materials)
      m.second.body_force->set_time(t);
  }


  template struct Material<2>;
  template struct Material<3>;
  template class Materials<2>;
  template class Materials<3>;
} // namespace knee_contact
