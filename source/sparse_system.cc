#include <knee_contact/active_set.h>
#include <knee_contact/contact_system.h>
#include <knee_contact/sparse_cholesky.h>

#include <deal.II/base/timer.h>

#include <algorithm>
#include <cmath>

namespace knee_contact
{
  class SparseContactSystem::Implementation
  {
  public:
    Implementation(const SparseMatrix<double>      &matrix,
                   const AffineConstraints<double> &base,
                   const std::vector<ContactPair>  &pairs)
      : matrix(matrix)
      , base(base)
      , pairs(pairs)
      , condensed(matrix.get_sparsity_pattern())
    {}

    const SparseMatrix<double>      &matrix;
    const AffineConstraints<double> &base;
    const std::vector<ContactPair>  &pairs;
    const Vector<double>            *rhs = nullptr;
    sparse_cholesky::SparseCholesky  cholesky;
    /** C condensed under the active set of the current factor. */
    SparseMatrix<double>      condensed;
    AffineConstraints<double> constraints;
    /** Whether there is a factor, and the active set it holds. */
    bool              has_factor = false;
    std::vector<bool> factored;
    Vector<double>    x;

    double       ordering = 0, analysis = 0, factorisation = 0, solves = 0;
    unsigned int n_factorisations = 0, n_solves = 0;
  };



  SparseContactSystem::SparseContactSystem(
    const SparseMatrix<double>      &matrix,
    const AffineConstraints<double> &base,
    const std::vector<ContactPair>  &pairs,
    std::vector<int>                 order)
    : implementation(std::make_unique<Implementation>(matrix, base, pairs))
  {
    Implementation &d = *implementation;
    // The pattern of every active set: each entry of the matrix's pattern,
    // values irrelevant for ordering and analysis.
    const auto pattern = sparse_cholesky::condense(
      matrix, AffineConstraints<double>(), /*keep_pattern=*/true);
    Timer clock;
    if (order.empty())
      order = sparse_cholesky::fill_reducing_ordering(pattern, {});
    d.ordering = clock.wall_time();
    clock.restart();
    d.cholesky.analyse(pattern, order, true);
    d.analysis = clock.wall_time();
  }



  SparseContactSystem::~SparseContactSystem() = default;



  void
  SparseContactSystem::set_rhs(const Vector<double> &rhs)
  {
    implementation->rhs = &rhs;
  }



  void
  SparseContactSystem::solve(const std::vector<bool> &active,
                             std::vector<double>     &excess,
                             std::vector<double>     &lambda)
  {
    Implementation &d = *implementation;
    Assert(d.rhs != nullptr, ExcMessage("set_rhs() was not called"));
    Timer clock;
    // The seed's constraint set (13) with the active rows as equalities,
    // each solved for its eliminated dof (as in step-41), condensed into C
    // on the one pattern; only a new active set needs a new factor.
    if (!d.has_factor || d.factored != active)
      {
        ActiveSetSolver::make_constraints(d.base,
                                          d.pairs,
                                          active,
                                          d.constraints);
        d.condensed.copy_from(d.matrix);
        d.constraints.condense(d.condensed);
        if (!d.cholesky.factorise(d.condensed))
          {
            d.has_factor = false;
            AssertThrow(false, ExcNotPositiveDefinite());
          }
        d.has_factor = true;
        d.factored   = active;
        d.factorisation += clock.wall_time();
        ++d.n_factorisations;
      }
    clock.restart();
    const auto b = sparse_cholesky::condense(d.matrix, *d.rhs, d.constraints);
    std::vector<double> z(b.begin(), b.end());
    d.cholesky.solve(CHOLMOD_A, z);
    d.x.reinit(z.size());
    std::copy(z.begin(), z.end(), d.x.begin());
    d.constraints.distribute(d.x);

    // The multipliers from the residual d - C x at the eliminated dofs, the
    // excess (A x - g)_p from the jumps, as the step-41 path.
    Vector<double> residual(d.rhs->size());
    d.matrix.residual(residual, d.x, *d.rhs);
    lambda = ActiveSetSolver::multipliers(residual, d.base, d.pairs, active);
    excess.resize(d.pairs.size());
    for (unsigned int p = 0; p < d.pairs.size(); ++p)
      excess[p] = d.pairs[p].jump(d.x) - d.pairs[p].gap;
    d.solves += clock.wall_time();
    ++d.n_solves;
  }



  double
  SparseContactSystem::displacement_scale() const
  {
    const Implementation &d     = *implementation;
    double                scale = 0;
    for (const auto &pair : d.pairs)
      if (pair.eliminated != numbers::invalid_dof_index)
        for (const auto &entry : pair.reduced_row)
          scale = std::max(scale, std::abs(d.x(entry.first)));
    return scale;
  }



  void
  SparseContactSystem::solution(Vector<double> &x)
  {
    x = implementation->x;
  }



  double
  SparseContactSystem::nnz_factor() const
  {
    return implementation->cholesky.nnz_factor();
  }



  double
  SparseContactSystem::flops() const
  {
    return implementation->cholesky.flops();
  }



  std::map<std::string, double>
  SparseContactSystem::statistics() const
  {
    const Implementation &d = *implementation;
    return {{"ordering", d.ordering},
            {"analysis", d.analysis},
            {"factorisation", d.factorisation},
            {"factorisations", d.n_factorisations},
            {"solves", d.n_solves},
            {"solve_and_multipliers", d.solves},
            {"factor_memory_MB", d.cholesky.memory_MB()},
            {"factor_flops", d.cholesky.flops()}};
  }
} // namespace knee_contact
