#ifndef knee_contact_sparse_cholesky_h
#define knee_contact_sparse_cholesky_h

#include <knee_contact/solver/sparse_factor.h>
#include <knee_contact/solver/stiffness.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <cholmod.h>

#include <cstddef>
#include <stdexcept>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The sparse direct algebra the contact solvers share: condensing C under
   * a set of constraint lines, a METIS fill-reducing ordering of the mesh
   * vertices, and CHOLMOD's supernodal Cholesky factor with its symbolic
   * analysis kept apart from the numeric factorisation (so that one
   * analysis serves every active set of a mesh).
   */
  namespace sparse_cholesky
  {
    /** A symmetric matrix in CSR over all dofs (both triangles). */
    struct CsrMatrix
    {
      std::vector<std::size_t>             row_start;
      std::vector<types::global_dof_index> column;
      std::vector<double>                  value;

      std::size_t
      size() const
      {
        return row_start.empty() ? 0 : row_start.size() - 1;
      }
    };

    /**
     * C under @p constraints, C0^T C C0 on the free dofs and a decoupled
     * diagonal on the constrained ones, as AffineConstraints::condense()
     * makes it; only its nonzero entries are kept (the pattern of the
     * matrix also holds the couplings of every active set, which would
     * only add fill).
     */
    CsrMatrix
    condense(const SparseMatrix<double>      &matrix,
             const AffineConstraints<double> &constraints);

    /**
     * The entries of @p pattern as a CsrMatrix without values: enough for
     * the ordering and the symbolic analysis, without copying a matrix.
     */
    CsrMatrix
    pattern_of(const SparsityPattern &pattern);

    /**
     * C0^T (d - C g) on the free dofs, zero on the constrained ones: the
     * right hand side of the condensed system for inhomogeneous lines
     * x_i = sum_j c_ij x_j + g_i (AffineConstraints condenses a vector
     * only for homogeneous lines); d - C g from @p residual.
     */
    Vector<double>
    condense(const StiffnessResidual         &residual,
             const Vector<double>            &rhs,
             const AffineConstraints<double> &constraints);

    /**
     * T^T v for closed lines, zero inhomogeneity: each constrained entry
     * added to the free entries its line refers to, then zeroed
     * (AffineConstraints::condense() of a vector without the
     * inhomogeneities, on a vector it may not own).
     */
    void
    condense_homogeneous(const AffineConstraints<double> &constraints,
                         Vector<double>                  &v);

    /**
     * T y for closed lines: each constrained entry from the free entries
     * its line refers to, without the inhomogeneity.
     */
    void
    distribute_homogeneous(const AffineConstraints<double> &constraints,
                           Vector<double>                  &v);

    /**
     * A fill-reducing ordering: METIS nested dissection of the graph of
     * mesh vertices (dofs with identical rows, the components of a vertex,
     * are ordered together, which makes METIS several times faster than on
     * the dofs), with the dofs in @p last (in their order) at the end.
     * Returns perm with perm[new position] = dof.
     */
    std::vector<int>
    fill_reducing_ordering(const CsrMatrix                            &a,
                           const std::vector<types::global_dof_index> &last);

    /**
     * A factor past CHOLMOD's 32-bit indices (more than 2^31 - 1 entries,
     * about 20 GB of values: a 3D mesh of about 1e6 dofs), found by
     * SparseCholesky::analyse().
     */
    class FactorTooLarge : public std::runtime_error
    {
    public:
      FactorTooLarge()
        : std::runtime_error("the sparse factor would have more than 2^31 "
                             "entries (CHOLMOD's 32-bit indices)")
      {}
    };

    /**
     * CHOLMOD's supernodal LL^T of a symmetric positive definite matrix in
     * a given order. analyse() once per pattern, then factorise() any
     * matrix of that pattern as often as needed.
     */
    class SparseCholesky : public SparseFactor
    {
    public:
      SparseCholesky();
      ~SparseCholesky() override;
      SparseCholesky(const SparseCholesky &) = delete;
      SparseCholesky &
      operator=(const SparseCholesky &) = delete;

      /**
       * Symbolic analysis of @p a's pattern in the order @p order
       * (perm[new] = dof); afterwards nnz_factor() and flops() tell the
       * cost of every factorisation of this pattern before it is made.
       * @p postorder lets CHOLMOD postorder the elimination tree, which
       * merges supernodes (measured: 2-3x faster factorisations); it
       * moves unknowns, so a caller that needs the last ones last (the
       * trailing block) passes false.
       */
      void
      analyse(const CsrMatrix        &a,
              const std::vector<int> &order,
              const bool              postorder);

      /**
       * Numeric factorisation of @p a (the analysed pattern) plus @p shift
       * on the diagonal of the last @p n_shifted dofs of the order; false
       * if not positive definite.
       */
      bool
      factorise(const CsrMatrix  &a,
                const std::size_t n_shifted = 0,
                const double      shift     = 0);

      /**
       * Numeric factorisation of @p a, whose sparsity pattern's entries
       * (zeros included) are the analysed pattern; false if not positive
       * definite.
       */
      bool
      factorise(const SparseMatrix<double> &a) override;

      /** Frees CHOLMOD's copy of the matrix (kept for refactorisation). */
      void
      release_matrix();

      /**
       * The last @p k dofs of the factor's final order (after
       * postordering), position by position.
       */
      std::vector<int>
      final_last(const std::size_t k) const;

      /** Entries of L and flops of one factorisation, from the analysis. */
      double
      nnz_factor() const;
      double
      flops() const;

      /**
       * The trailing k x k block of L (positions n-k..n-1), dense,
       * column-major, lower triangle.
       */
      std::vector<double>
      trailing_block(const std::size_t k) const;

      /** Memory of the factor's values and row indices [MB]. */
      double
      memory_MB() const override;

      /** b = solve(system, b) for CHOLMOD_P, _L, _Lt, _Pt, _A. */
      void
      solve(const int system, std::vector<double> &b);

      /** b = A^-1 b (CHOLMOD_A). */
      void
      solve(std::vector<double> &b) override
      {
        solve(CHOLMOD_A, b);
      }

    private:
      void
      check(const char *what);

      /** cholmod_factorize on the values in matrix->x. */
      bool
      factorise_values();

      cholmod_common   common;
      cholmod_sparse  *matrix = nullptr;
      cholmod_factor  *factor = nullptr;
      std::vector<int> order;
      double           lnz = 0, fl = 0;
    };
  } // namespace sparse_cholesky
} // namespace knee_contact

#endif
