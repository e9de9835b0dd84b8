#ifndef knee_contact_rigid_modes_h
#define knee_contact_rigid_modes_h

#include <knee_contact/contact/contact_row.h>

#include <deal.II/base/index_set.h>
#include <deal.II/base/mpi.h>

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
     * On a distributed mesh collective (each rank evaluates the rows on
     * the dofs it owns), with the same answer on every rank.
     */
    virtual std::string
    free_motion(const AffineConstraints<double> &base,
                const std::vector<ContactRow>   &rows,
                const std::vector<bool>         &active) const = 0;

    /**
     * The rigid motions of the mesh at the dofs of @p rows (dofs this
     * rank knows: on a distributed mesh its locally relevant ones), one
     * after the other: motion k at the i-th dof of @p rows is entry
     * k * rows.n_elements() + i (ML's near null space). The translations
     * along the axes, then the rotations about the axes through each
     * body's centre scaled by its size (three in 2D, six in 3D); every
     * body's stiffness matrix maps them to zero.
     */
    virtual std::vector<double>
    rigid_motions(const IndexSet &rows) const = 0;

    /** The number of rigid motions rigid_motions() gives. */
    virtual unsigned int
    n_rigid_motions() const = 0;

    /** Dofs per vertex (the dimension). */
    virtual unsigned int
    components() const = 0;

    /**
     * Throw an ExcMessage naming the body and the free motion if the
     * constraints leave one. @p context ends the message (what the user can
     * do).
     */
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

    std::vector<double>
    rigid_motions(const IndexSet &rows) const override;

    unsigned int
    n_rigid_motions() const override
    {
      return n_modes;
    }

    unsigned int
    components() const override
    {
      return dim;
    }

    /** Modes per body: translations, then rotations. */
    static constexpr unsigned int n_modes = dim * (dim + 1) / 2;

  private:
    /** A distributed mesh's communicator (free_motion() is collective
     * there), else MPI_COMM_SELF. */
    MPI_Comm communicator = MPI_COMM_SELF;
    bool     distributed  = false;
    /** The dofs this rank owns (every dof on a whole mesh), and those it
     * knows (a distributed mesh's locally relevant ones: 1/N of the dofs
     * and a layer, where they were every dof, 32 bytes each, on every
     * rank until 2026-12-07). */
    IndexSet owned, known;
    /** By position in known: the dof's body, component and position. */
    std::vector<unsigned int> dof_body;
    std::vector<unsigned int> dof_component;
    std::vector<Point<dim>>   dof_position;
    std::vector<Point<dim>>   centre;
    std::vector<double>       size;
    std::vector<std::string>  names;

    /** The position in known of @p dof, which this rank must know. */
    std::size_t
    at(const types::global_dof_index dof) const;

    /** A body's n_modes values (of the modes at a dof, or summed). */
    struct ModeValues
    {
      unsigned int body;
      double       w[n_modes];
    };

    /** The modes' values at @p dof, which this rank must know. */
    ModeValues
    modes_at(const types::global_dof_index dof) const;
  };
} // namespace knee_contact

#endif
