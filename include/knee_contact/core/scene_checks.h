#ifndef knee_contact_scene_checks_h
#define knee_contact_scene_checks_h

#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/materials.h>

#include <deal.II/grid/tria.h>

#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Checks that need more than one concept of the scene: a scene that cannot
   * mean what it says is refused before the solve, with one line that names
   * the parameter, id or place.
   */
  namespace scene_checks
  {
    /**
     * A contact side (Gamma_c) is not also Gamma_u, Gamma_tau or Gamma_o:
     * one boundary id has one role (the contact would be switched off by a
     * displacement or sliding line, or a load counted twice).
     */
    template <int dim>
    void
    check_roles(const BoundaryConditions<dim> &conditions,
                const ContactInterfaces       &interfaces);

    /**
     * Body forces, tractions, pressures and prescribed displacements are
     * finite everywhere they are used: at every vertex and 2-point Gauss
     * point of every cell (body force) and boundary face of their ids, not
     * at one sample point.
     */
    template <int dim>
    void
    check_finite_data(const Triangulation<dim>      &triangulation,
                      const Materials<dim>          &materials,
                      const BoundaryConditions<dim> &conditions);

    /**
     * Cells meet along whole edges: two bodies (or two parts of one body)
     * that touch only at a vertex, and boundary edges of one body that lie
     * on top of each other (bonded edges whose vertices do not match: a
     * crack; 2D only, see check_cracks) are refused with the place. For a
     * mesh without hanging nodes.
     */
    template <int dim>
    void
    check_joints(const Triangulation<dim>        &triangulation,
                 const std::vector<unsigned int> &body_of_cell);

    /**
     * The crack test of check_joints() in 2D: boundary edges of one body
     * that overlap. (3D would need the overlap of coplanar boundary faces.)
     */
    void
    check_cracks(const Triangulation<2>          &triangulation,
                 const std::vector<unsigned int> &body_of_cell);
  } // namespace scene_checks
} // namespace knee_contact

#endif
