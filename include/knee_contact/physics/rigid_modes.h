#ifndef knee_contact_rigid_modes_h
#define knee_contact_rigid_modes_h

#include <knee_contact/contact/contact_row.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The test the active-set loop asks before it factorises: does a rigid
   * motion stay free of every constraint? Dimension-free, so that the
   * solver is; RigidModes<dim> answers it.
   */
  class RigidModeCheck
  {
  public:
    virtual ~RigidModeCheck() = default;

    /**
     * The description of the first free motion under @p base and the
     * active rows of @p rows, or an empty string if every body is held.
     */
    virtual std::string
    free_motion(const AffineConstraints<double> &base,
                const std::vector<ContactRow>   &rows,
                const std::vector<bool>         &active) const = 0;

    /**
     * Throw an ExcMessage naming the body and the free motion if the
     * constraints leave one. @p context ends the message (what the user can
     * do).
     */
    /**
     * The rigid motions of the whole mesh as dof vectors: the translations
     * along the axes, then the rotations about the axes through the mesh's
     * centre scaled by its size (three in 2D, six in 3D); every body's
     * stiffness matrix maps them to zero. The near null space of AMG.
     */
    virtual std::vector<Vector<double>>
    rigid_motions() const = 0;

    /** Dofs per vertex (the dimension). */
    virtual unsigned int
    components() const = 0;

    void
    check(const AffineConstraints<double> &base,
          const std::vector<ContactRow>   &rows,
          const std::vector<bool>         &active,
          const std::string               &context) const;
  };



  /**
   * Detects rigid motions that no constraint holds, before a factorisation
   * would fail or return garbage (the seed's Remark 5: C is only positive
   * semidefinite per body). Every body has dim (dim + 1) / 2 translations
   * and dim (dim - 1) / 2 rotations: three in 2D, six in 3D; the system is
   * solvable iff no combination of them satisfies all Gamma_u, Gamma_o and
   * active contact rows homogeneously. The test is the null space of the
   * small Gram matrix of those rows evaluated on the modes.
   */
  template <int dim>
  class RigidModes : public RigidModeCheck
  {
  public:
    RigidModes(const DoFHandler<dim>           &dof_handler,
               const std::vector<unsigned int> &body_of_cell,
               const std::vector<std::string>  &body_names);

    std::string
    free_motion(const AffineConstraints<double> &base,
                const std::vector<ContactRow>   &rows,
                const std::vector<bool>         &active) const override;

    std::vector<Vector<double>>
    rigid_motions() const override;

    unsigned int
    components() const override
    {
      return dim;
    }

    /** Modes per body: translations, then rotations. */
    static constexpr unsigned int n_modes = dim * (dim + 1) / 2;

  private:
    std::vector<unsigned int> dof_body;
    std::vector<unsigned int> dof_component;
    std::vector<Point<dim>>   dof_position;
    std::vector<Point<dim>>   centre;
    std::vector<double>       size;
    std::vector<std::string>  names;
  };
} // namespace knee_contact

#endif
