#ifndef knee_contact_sparse_factor_h
#define knee_contact_sparse_factor_h

#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Which library factorises the sparse path's matrix (Contact/Direct
   * factor): CHOLMOD's supernodal Cholesky, whole on every rank, or
   * MUMPS's multifrontal LDL^T, its factor distributed over the ranks;
   * automatic takes MUMPS on more than one rank.
   */
  enum class DirectFactor
  {
    automatic,
    cholmod,
    mumps
  };

  /** "automatic", "CHOLMOD", "MUMPS". */
  std::string
  direct_factor_name(const DirectFactor factor);

  /** The library @p requested stands for on this run's rank count. */
  DirectFactor
  resolve_direct_factor(const DirectFactor requested);



  /**
   * The seam of the sparse direct factor: the numeric factorisation of a
   * symmetric positive definite matrix of one fixed pattern, as often as the
   * active sets need, and solves with it. The matrix and the vectors are
   * whole on every rank; a distributed factor takes its rows of them.
   */
  class SparseFactor
  {
  public:
    virtual ~SparseFactor() = default;

    /**
     * Numeric factorisation of @p a, whose pattern's entries (zeros
     * included) are those of every call; false if it is not positive
     * definite. Collective.
     */
    virtual bool
    factorise(const SparseMatrix<double> &a) = 0;

    /** b = A^-1 b, b whole on every rank. Collective. */
    virtual void
    solve(std::vector<double> &b) = 0;

    /** Memory of the factor on this rank [MB]. */
    virtual double
    memory_MB() const = 0;

    /**
     * The factor's own figures for summary.json (its estimate of its
     * memory, the ranks it spans), by name.
     */
    virtual std::map<std::string, double>
    statistics() const
    {
      return {};
    }
  };



  /**
   * MUMPS's factor, distributed over the ranks of parallel::communicator()
   * (rank r gives rows [r n / N, (r + 1) n / N) of the matrix and holds its
   * share of the factor), for the pattern of @p pattern in the pivot order
   * @p order (perm[position] = dof: the METIS order of CHOLMOD's
   * analysis). Collective.
   */
  std::unique_ptr<SparseFactor>
  make_mumps_factor(const SparsityPattern  &pattern,
                    const std::vector<int> &order);
} // namespace knee_contact

#endif
