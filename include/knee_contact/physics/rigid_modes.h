#ifndef knee_contact_rigid_modes_h
#define knee_contact_rigid_modes_h

#include <knee_contact/contact/contact.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_handler.h>

#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Detects rigid motions that no constraint holds, before a factorisation
   * would fail or return garbage (the seed's Remark 5: C is only positive
   * semidefinite per body). Every body has three rigid modes (translation in
   * x and y, rotation); the system is solvable iff no combination of them
   * satisfies all Gamma_u, Gamma_o and active contact rows homogeneously.
   * The test is the null space of the small Gram matrix of those rows
   * evaluated on the modes.
   */
  class RigidModes
  {
  public:
    RigidModes(const DoFHandler<2>             &dof_handler,
               const std::vector<unsigned int> &body_of_cell,
               const std::vector<std::string>  &body_names);

    /**
     * Throw an ExcMessage naming the body and the free motion if the
     * constraints leave one. @p context ends the message (what the user can
     * do).
     */
    void
    check(const AffineConstraints<double> &base,
          const std::vector<ContactPair>  &pairs,
          const std::vector<bool>         &active,
          const std::string               &context) const;

    /**
     * The same test; returns the description of the first free motion, or
     * an empty string if every body is held.
     */
    std::string
    free_motion(const AffineConstraints<double> &base,
                const std::vector<ContactPair>  &pairs,
                const std::vector<bool>         &active) const;

  private:
    std::vector<unsigned int> dof_body;
    std::vector<unsigned int> dof_component;
    std::vector<Point<2>>     dof_position;
    std::vector<Point<2>>     centre;
    std::vector<double>       size;
    std::vector<std::string>  names;
  };
} // namespace knee_contact

#endif
