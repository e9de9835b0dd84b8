#ifndef knee_contact_row_multipliers_h
#define knee_contact_row_multipliers_h

#include <knee_contact/contact/contact_row.h>
#include <knee_contact/solver/contact_system.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_direct.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <functional>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The multipliers of the active rows of a path that eliminates them (one
   * dof e_q per active row q: step-41, sparse, iterative), from a residual
   * r = d - C x:
   *   (M + E B) lambda = E r,
   * E r = (C0^T r)(e_q) (C0 the Gamma_u/Gamma_o substitution),
   * M = E A^T (the rows' reduced coefficients at the eliminated dofs: the
   * identity up to scaling unless rows share eliminated dofs) and B the
   * bound couplings' columns: a coupled pair's force is
   * lambda_n (a_N + sum_j c_j a_T_j) (ContactSystem::BoundCoupling), B's
   * column is sum_j c_j a_T_j on the full rows, zero for the others.
   *
   * With couplings the condensed equations T^T r = 0 become
   * T^T (r - B lambda(r)) = 0, T^T (I - B (M + E B)^-1 E) (d - C x) = 0:
   * project() applies the bracket to a residual or product before the
   * constraints fold it (unsymmetric: the Krylov paths take GMRES).
   *
   * Written here: deal.II's AffineConstraints condenses with the rows
   * themselves as the test space; a Petrov-Galerkin elimination with other
   * force directions is not in it. The small system is UMFPACK's.
   */
  class RowMultipliers
  {
  public:
    RowMultipliers(
      const AffineConstraints<double>                 &base,
      const std::vector<ContactRow>                   &rows,
      const std::vector<bool>                         &active,
      const std::vector<ContactSystem::BoundCoupling> &couplings = {});

    /** Whether there are couplings (else project() is the identity). */
    bool
    coupled() const
    {
      return !b_entries.empty();
    }

    /** lambda of every row (zero for the inactive) of r = d - C x. */
    std::vector<double>
    operator()(const Vector<double> &residual) const;

    /** r -= B (M + E B)^-1 E r (one process: r whole). */
    void
    project(Vector<double> &r) const;

    /**
     * The same in three steps for a residual spread over ranks: E r over
     * the entries @p has reports (each rank its own, summed by the
     * caller)...
     */
    Vector<double>
    gather(const std::function<bool(types::global_dof_index)>   &has,
           const std::function<double(types::global_dof_index)> &value) const;

    /** ...(M + E B)^-1 on the sum, in place... */
    void
    solve(Vector<double> &t) const;

    /** ...and -B z added through @p add (each rank its own entries). */
    void
    scatter(
      const Vector<double>                                       &z,
      const std::function<void(types::global_dof_index, double)> &add) const;

  private:
    /** t_q += coefficient r_i: (i, q, coefficient). */
    struct Entry
    {
      types::global_dof_index dof;
      unsigned int            equation;
      double                  coefficient;
    };
    std::vector<Entry> e_entries;
    /** B's entries: r_i -= coefficient z_q. */
    std::vector<Entry>    b_entries;
    std::vector<unsigned> equation_of_row;
    unsigned int          n_equations = 0;
    SparsityPattern       sparsity;
    SparseMatrix<double>  matrix;
    SparseDirectUMFPACK   factor;
  };
} // namespace knee_contact

#endif
