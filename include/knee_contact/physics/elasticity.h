#ifndef knee_contact_elasticity_h
#define knee_contact_elasticity_h

#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/materials.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <functional>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Assembles the seed's quadratic functional L(v) = 1/2 a(v,v) - L(v), its
   * eq. (7), as the stiffness matrix C and load vector d of
   * f(x) = 1/2 x^T C x - x^T d, without any constraint applied: the
   * active-set loop condenses a copy for each active set and needs the
   * unconstrained pair for the residual d - C x (reactions and contact
   * forces).
   */
  template <int dim>
  class ElasticityAssembler
  {
  public:
    ElasticityAssembler(const Materials<dim>          &materials,
                        const BoundaryConditions<dim> &boundary_conditions);

    /**
     * @p matrix must be initialised with a sparsity pattern; it and @p rhs
     * are overwritten. Cells are assembled in parallel by WorkStream.
     */
    void
    assemble(const DoFHandler<dim> &dof_handler,
             SparseMatrix<double>  &matrix,
             Vector<double>        &rhs) const;

    /**
     * Only the load vector d, for a further load case on the same mesh:
     * the body forces and tractions at the load parameter last set. On a
     * distributed mesh each rank assembles its cells and every rank gets
     * the whole d.
     */
    void
    assemble_rhs(const DoFHandler<dim> &dof_handler, Vector<double> &rhs) const;

    /**
     * The cell matrices of the cells with a dof @p wanted says yes to,
     * each given to @p add(dofs, cell matrix) as it is made (one call at
     * a time; the cells in parallel by WorkStream): the rows a rank holds
     * of C, summed where they are kept (IterativeContactSystem on several
     * ranks), without C whole. On a distributed mesh (DistributedMesh):
     * of the cells this rank owns.
     */
    void
    assemble_cells(
      const DoFHandler<dim>                                    &dof_handler,
      const std::function<bool(const types::global_dof_index)> &wanted,
      const std::function<void(const std::vector<types::global_dof_index> &,
                               const FullMatrix<double> &)>    &add) const;

  private:
    struct Sinks;

    void
    assemble(const DoFHandler<dim> &dof_handler, const Sinks &sinks) const;

    const Materials<dim>          &materials;
    const BoundaryConditions<dim> &boundary_conditions;
  };
} // namespace knee_contact

#endif
