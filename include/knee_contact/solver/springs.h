#ifndef knee_contact_springs_h
#define knee_contact_springs_h

#include <knee_contact/contact/contact_row.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/stiffness.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <functional>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * A spring of ContactSystem::Spring on the dofs: energy
   * 1/2 k (w . x - g_w)^2, w = sum_r c_r a'_r over the rows' reduced rows
   * (the dofs Gamma_u and Gamma_o leave free), g_w the same sum of their
   * reduced gaps. The condensed path adds it to its Schur complement; the
   * paths that solve for the whole x (step-41, sparse, iterative) add
   * k w w^T to their matrix or operator, k g_w w to the right hand side,
   * and its force to the residual their multipliers are read from.
   */
  struct SpringTerm
  {
    std::vector<std::pair<types::global_dof_index, double>> w;
    double                                                  g_w       = 0;
    double                                                  stiffness = 0;

    double
    dot(const Vector<double> &x) const
    {
      return sparse_dot(w, x);
    }
  };

  namespace springs
  {
    /** The springs @p springs on the rows @p pairs, on the dofs. */
    std::vector<SpringTerm>
    on_dofs(const std::vector<ContactSystem::Spring> &springs,
            const std::vector<ContactRow>            &pairs);

    /**
     * Whether @p a and @p b are the same springs up to their gaps (the
     * same matrix k w w^T: a factor of it stays valid).
     */
    bool
    same_matrix(const std::vector<SpringTerm> &a,
                const std::vector<SpringTerm> &b);

    /**
     * matrix += sum k w w^T. The pattern must hold every w's dofs coupled
     * (ActiveSetSolver::make_sparsity_pattern with the springs' row
     * groups); an entry it lacks is an internal error, not dropped.
     */
    void
    add_to_matrix(const std::vector<SpringTerm> &springs,
                  SparseMatrix<double>          &matrix);

    /** v += sum k (g_w - w . x) w: the springs' forces at @p x. */
    void
    add_forces(const std::vector<SpringTerm> &springs,
               const Vector<double>          &x,
               Vector<double>                &v);

    /**
     * The condensed load of K x = d + sum k g_w w under @p constraints (C
     * through @p residual):
     * T^T (d + sum k g_w w - K g), g the constraints' inhomogeneities
     * (sparse_cholesky::condense() with the springs' forces at g);
     * @p before_folding, if given, changes the whole vector
     * d + sum k g_w w - K g before T^T folds it (the bound couplings'
     * projection, RowMultipliers::project()).
     */
    Vector<double>
    condensed_load(
      const std::vector<SpringTerm>               &springs,
      const StiffnessResidual                     &residual,
      const Vector<double>                        &rhs,
      const AffineConstraints<double>             &constraints,
      const std::function<void(Vector<double> &)> &before_folding = {});

    /**
     * The springs of @p springs (on_dofs() of @p rows' springs) stiff
     * beside the matrix, held as equalities instead: what a Krylov solver
     * is left with by the others, and what it recovers afterwards.
     */
    struct Ties
    {
      /** The springs kept as springs (every other: tied). */
      std::vector<SpringTerm> kept;
      /**
       * One row per tied spring, appended to the contact rows and held
       * active: w . x = g_w. For the constraints its reduced row is w with
       * the active rows that share its dofs subtracted (no row then holds
       * another's eliminated dof: AffineConstraints has no cycles to
       * close); for the multipliers, w itself.
       */
      std::vector<ContactRow> for_constraints, for_multipliers;
      /** Of each tied spring: its stiffness and its rows (r, c_r). */
      std::vector<double>                                       stiffness;
      std::vector<std::vector<std::pair<unsigned int, double>>> rows;
    };

    /**
     * Ties the springs whose stiffness on their own combination w exceeds
     * @p ratio times the matrix's (k |w|^4 >= ratio sum_i w_i^2 C_ii, C_ii
     * = @p diagonal(i)): each
     * adds one large eigenvalue to K = C + sum k w w^T, which AMG on C does
     * not see, and CG pays for them (the 3D knee's stance at 34 059 dofs:
     * up to 4 682 iterations a solve, against 100 without friction). Held as w
     * . x = g_w instead, the spring's stretch is its multiplier divided by k:
     * the semismooth Newton step with k -> infinity across the slip, which
     * changes the step by about C/k, at most 1/ratio. A spring is kept where no
     * dof of w is free to eliminate (or would be, after more than eight
     * row subtractions). The rows subtracted may bring dofs of their own
     * (a neighbouring pair's normal row), couplings the matrix pattern
     * may lack: the hierarchy built on it then misses them, the operator
     * does not.
     */
    Ties
    tie_stiff(const std::vector<ContactSystem::Spring>             &springs,
              const std::vector<SpringTerm>                        &terms,
              const std::vector<ContactRow>                        &rows,
              const std::vector<bool>                              &active,
              const std::function<double(types::global_dof_index)> &diagonal,
              const double                                          ratio);

    /**
     * After a solve with @p ties held (their multipliers at
     * @p lambda[n_rows + t]): adds each tied spring's stretch
     * lambda / k to the excess of its rows, as the spring would have
     * stretched (w . x - g_w = sum_r c_r excess_r), and drops the tied
     * rows from @p excess and @p lambda.
     */
    void
    untie(const Ties          &ties,
          const unsigned int   n_rows,
          std::vector<double> &excess,
          std::vector<double> &lambda);

    /** v += sum k (w . x) w. */
    void
    vmult_add(const std::vector<SpringTerm> &springs,
              const Vector<double>          &x,
              Vector<double>                &v);
  } // namespace springs
} // namespace knee_contact

#endif
