#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/row_multipliers.h>
#include <knee_contact/solver/sparse_cholesky.h>
#include <knee_contact/solver/springs.h>

#include <deal.II/base/timer.h>

#include <deal.II/lac/lapack_templates.h>
#include <deal.II/lac/solver_cg.h>
#include <deal.II/lac/solver_control.h>
#include <deal.II/lac/solver_gmres.h>

#include <algorithm>
#include <cmath>
#include <map>

namespace knee_contact
{
  namespace
  {
    using SparseVector =
      std::vector<std::pair<types::global_dof_index, double>>;

    /** u^T v of two sparse vectors sorted by index. */
    double
    dot(const SparseVector &u, const SparseVector &v)
    {
      double sum = 0;
      for (auto i = u.begin(), j = v.begin(); i != u.end() && j != v.end();)
        if (i->first < j->first)
          ++i;
        else if (j->first < i->first)
          ++j;
        else
          sum += (i++)->second * (j++)->second;
      return sum;
    }

    /** u^T v of a sparse and a full vector. */
    double
    dot(const SparseVector &u, const Vector<double> &v)
    {
      double sum = 0;
      for (const auto &[i, value] : u)
        sum += value * v(i);
      return sum;
    }

    /** The nonzero entries of @p v, sorted. */
    SparseVector
    sparse(const Vector<double> &v)
    {
      SparseVector result;
      for (types::global_dof_index i = 0; i < v.size(); ++i)
        if (v(i) != 0)
          result.emplace_back(i, v(i));
      return result;
    }

    /**
     * (C + sum k w w^T) v for a sparse v (C symmetric: its rows serve as
     * columns).
     */
    SparseVector
    multiply(const SparseMatrix<double>    &c,
             const std::vector<SpringTerm> &springs,
             const SparseVector            &v)
    {
      std::map<types::global_dof_index, double> sum;
      for (const auto &[j, value] : v)
        for (auto it = c.begin(j); it != c.end(j); ++it)
          sum[it->column()] += it->value() * value;
      for (const auto &spring : springs)
        {
          const double stretch = spring.stiffness * dot(spring.w, v);
          if (stretch != 0)
            for (const auto &[i, a] : spring.w)
              sum[i] += stretch * a;
        }
      return SparseVector(sum.begin(), sum.end());
    }

  } // namespace



  class SparseContactSystem::Implementation
  {
  public:
    Implementation(const SparseMatrix<double>      &matrix,
                   const AffineConstraints<double> &base,
                   const std::vector<ContactRow>   &pairs)
      : matrix(matrix)
      , base(base)
      , pairs(pairs)
    {}

    /** The factor of the solves: MUMPS's if made, else CHOLMOD's. */
    SparseFactor &
    factor()
    {
      return distributed ? *distributed : cholesky;
    }
    const SparseFactor &
    factor() const
    {
      if (distributed)
        return *distributed;
      return cholesky;
    }

    const SparseMatrix<double>      &matrix;
    const AffineConstraints<double> &base;
    const std::vector<ContactRow>   &pairs;
    const Vector<double>            *rhs = nullptr;
    /**
     * CHOLMOD's analysis (the cost estimates of the path) and, unless
     * MUMPS's factor is taken, its factorisations.
     */
    sparse_cholesky::SparseCholesky cholesky;
    /** MUMPS's factor, distributed over the ranks (Contact/Direct
     * factor). */
    std::unique_ptr<SparseFactor> distributed;
    std::vector<int>              order;
    /** C condensed under the base active set A0 of the factor. */
    SparseMatrix<double>      condensed;
    AffineConstraints<double> constraints;
    bool                      has_factor = false;
    std::vector<bool>         base_active;
    /**
     * The springs of the following solves (set_springs()): the matrix is
     * K = C + sum k w w^T and the load d + sum k g_w w throughout.
     */
    std::vector<SpringTerm> springs;
    /** The springs in the factor (those of its factorisation). */
    std::vector<SpringTerm> factor_springs;

    /** K x (C and the springs). */
    void
    vmult(Vector<double> &dst, const Vector<double> &x) const
    {
      matrix.vmult(dst, x);
      springs::vmult_add(springs, x, dst);
    }

    /** d + sum k g_w w - K x = d - C x + sum k (g_w - w x) w. */
    void
    residual(Vector<double> &dst, const Vector<double> &x) const
    {
      matrix.residual(dst, x, *rhs);
      springs::add_forces(springs, x, dst);
    }

    /**
     * A correction of the base space for one pair whose state differs
     * from A0: a released row r (the direction delta_r that frees its
     * eliminated dof, C delta_r) or an added row p (its row a_p), and
     * w = T K0^-1 T^T (C delta_r or a_p), one solve with the factor.
     */
    struct Correction
    {
      bool           released = false;
      SparseVector   v;  // delta_r or a_p
      SparseVector   cv; // C delta_r (released rows)
      Vector<double> w;
    };
    std::map<unsigned int, Correction> corrections;

    /** The base solution x0 for the current load and f - C x0. */
    bool           base_solved = false;
    Vector<double> x0, residual0;
    Vector<double> x;

    double ordering = 0, analysis = 0, factorisation = 0, solves = 0,
           updates = 0, stale_factor_time = 0;
    unsigned int n_stale_factor_solves = 0, stale_factor_iterations = 0;
    unsigned int n_factorisations = 0, n_solves = 0, n_updates = 0,
                 n_corrections = 0, n_updates_on_factor = 0, n_spring_sets = 0;

    void
    factorise(const std::vector<bool> &active);

    /** One solve with the factor: T K0^-1 T^T b (b overwritten). */
    void
    solve_base_homogeneous(Vector<double> &b);

    /**
     * Solve the factor's active set with the springs set now,
     * T^T K T y = b, or with @p coupling its Coulomb couplings too,
     * T^T (I - B (M + E B)^-1 E) K T y = b (RowMultipliers): CG (GMRES)
     * preconditioned by the factor, from @p y, to 1e-12 of b; false if it
     * does not converge in @p max_iterations.
     */
    bool
    solve_on_factor(const Vector<double> &b,
                    Vector<double>       &y,
                    const RowMultipliers *coupling,
                    const unsigned int    max_iterations);

    /**
     * The Krylov iterations half a factorisation costs: each about one
     * correction's solve (16 nnz(L) flops at the factorisation's rate,
     * measured: see solve()) and a product with K.
     */
    unsigned int
    krylov_budget() const
    {
      const double per_iteration =
        16 * cholesky.nnz_factor() + 2. * matrix.n_nonzero_elements();
      return static_cast<unsigned int>(
        std::max(5., 0.5 * cholesky.flops() / per_iteration));
    }

    /** The bound couplings of the following solves. */
    std::vector<ContactSystem::BoundCoupling> couplings;
    unsigned int n_coupled_solves = 0, coupled_iterations = 0;
    double       coupled_time = 0;

    Correction
    make_correction(const unsigned int p);
  };



  void
  SparseContactSystem::Implementation::factorise(
    const std::vector<bool> &active)
  {
    Timer clock;
    // The seed's constraint set (13) with the active rows as equalities,
    // each solved for its eliminated dof (as in step-41), condensed into C
    // on the one pattern of every active set.
    ActiveSetSolver::make_constraints(base, pairs, active, constraints);
    if (!has_factor && n_factorisations == 0)
      condensed.reinit(matrix.get_sparsity_pattern());
    condensed.copy_from(matrix);
    springs::add_to_matrix(springs, condensed);
    constraints.condense(condensed);
    factor_springs = springs;
    has_factor     = false;
    if (!factor().factorise(condensed))
      AssertThrow(false, ExcNotPositiveDefinite());
    has_factor  = true;
    base_active = active;
    corrections.clear();
    n_updates_on_factor = 0;
    base_solved         = false;
    factorisation += clock.wall_time();
    ++n_factorisations;
  }



  void
  SparseContactSystem::Implementation::solve_base_homogeneous(Vector<double> &b)
  {
    sparse_cholesky::condense_homogeneous(constraints, b);
    std::vector<double> z(b.begin(), b.end());
    factor().solve(z);
    std::copy(z.begin(), z.end(), b.begin());
    sparse_cholesky::distribute_homogeneous(constraints, b);
  }



  bool
  SparseContactSystem::Implementation::solve_on_factor(
    const Vector<double> &b,
    Vector<double>       &y,
    const RowMultipliers *coupling,
    const unsigned int    max_iterations)
  {
    // Why: the semismooth Newton step of 3D friction sets new spring
    // stiffnesses at every iteration while the active set mostly stays (a
    // slipping pair is active by its normal row alone). K differs from the
    // factor's matrix by the change of the springs, sum dk w w^T, so the
    // factor is a preconditioner that CG needs few iterations with; a
    // factorisation costs as much as hundreds of its solves in 3D. The
    // Newton step on the Coulomb bound changes T^T K T by the couplings'
    // low-rank term only: GMRES on the factor of the set takes 5 to 11
    // iterations a solve (3D and 2D knees).
    // (T^T (I - Q) K T y: y spread over the constrained lines, K applied,
    // projected, the constrained lines folded back; they stay zero, as the
    // factor keeps them.)
    struct Operator
    {
      const Implementation &d;
      const RowMultipliers *coupling;
      void
      vmult(Vector<double> &dst, const Vector<double> &src) const
      {
        Vector<double> spread = src;
        sparse_cholesky::distribute_homogeneous(d.constraints, spread);
        d.vmult(dst, spread);
        if (coupling != nullptr)
          coupling->project(dst);
        sparse_cholesky::condense_homogeneous(d.constraints, dst);
      }
    };
    struct Preconditioner
    {
      SparseFactor &factor;
      void
      vmult(Vector<double> &dst, const Vector<double> &src) const
      {
        std::vector<double> z(src.begin(), src.end());
        factor.solve(z);
        std::copy(z.begin(), z.end(), dst.begin());
      }
    };
    Timer          clock;
    SolverControl  control(max_iterations,
                          1e-12 * std::max(b.l2_norm(), 1e-300),
                          false,
                          false);
    const Operator operation{*this, coupling};
    bool           converged = true;
    try
      {
        if (coupling != nullptr)
          SolverGMRES<Vector<double>>(
            control,
            SolverGMRES<Vector<double>>::AdditionalData(
              IterativeContactSystem::gmres_basis, true))
            .solve(operation, y, b, Preconditioner{factor()});
        else
          SolverCG<Vector<double>>(control).solve(operation,
                                                  y,
                                                  b,
                                                  Preconditioner{factor()});
      }
    catch (const SolverControl::NoConvergence &)
      {
        converged = false;
      }
    const bool stale = !springs::same_matrix(springs, factor_springs);
    if (coupling != nullptr)
      {
        coupled_time += clock.wall_time();
        coupled_iterations += control.last_step();
        n_coupled_solves += converged;
      }
    else
      {
        stale_factor_time += clock.wall_time();
        stale_factor_iterations += control.last_step();
      }
    n_stale_factor_solves += converged && stale;
    return converged;
  }



  SparseContactSystem::Implementation::Correction
  SparseContactSystem::Implementation::make_correction(const unsigned int p)
  {
    Correction     c;
    Vector<double> w(matrix.m());
    c.released = base_active[p];
    if (c.released)
      {
        // delta_r: x_e = 1 at the eliminated dof, every other free dof of
        // A0 \ {r} zero, the lines that refer to e (a hanging node on it,
        // a row eliminating a dof through it) following. It lies in the
        // space of A0 \ R for any released set R containing r, and its
        // excess a_r^T delta_r = a_r(e) is nonzero, so the deltas of R
        // and the base space span that space.
        std::vector<bool> without = base_active;
        without[p]                = false;
        AffineConstraints<double> lines;
        ActiveSetSolver::make_constraints(base, pairs, without, lines);
        Vector<double> zero(matrix.m()), unit(matrix.m());
        unit(pairs[p].eliminated) = 1;
        lines.distribute(unit);
        lines.distribute(zero);
        unit -= zero;
        c.v  = sparse(unit);
        c.cv = multiply(matrix, springs, c.v);
        for (const auto &[i, value] : c.cv)
          w(i) = value;
      }
    else
      {
        c.v = SparseVector(pairs[p].reduced_row.begin(),
                           pairs[p].reduced_row.end());
        std::sort(c.v.begin(), c.v.end());
        for (const auto &[i, value] : c.v)
          w(i) += value;
      }
    solve_base_homogeneous(w);
    c.w = std::move(w);
    ++n_corrections;
    return c;
  }



  SparseContactSystem::SparseContactSystem(
    const SparseMatrix<double>      &matrix,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs)
    : SparseContactSystem(matrix, matrix.get_sparsity_pattern(), base, pairs)
  {}



  SparseContactSystem::SparseContactSystem(
    const SparseMatrix<double>      &matrix,
    const SparsityPattern           &sparsity,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs)
    : implementation(std::make_unique<Implementation>(matrix, base, pairs))
  {
    Implementation &d = *implementation;
    // The pattern of every active set: each entry of the matrix's pattern.
    const auto pattern = sparse_cholesky::pattern_of(sparsity);
    Timer      clock;
    d.order    = sparse_cholesky::fill_reducing_ordering(pattern, {});
    d.ordering = clock.wall_time();
    clock.restart();
    d.cholesky.analyse(pattern, d.order, true);
    d.analysis = clock.wall_time();
  }



  void
  SparseContactSystem::use_mumps()
  {
    Implementation &d = *implementation;
    Assert(d.n_factorisations == 0, ExcInternalError());
    Timer clock;
    d.distributed = make_mumps_factor(d.matrix.get_sparsity_pattern(), d.order);
    // CHOLMOD keeps its analysis (the estimates), not its copy of C.
    d.cholesky.release_matrix();
    d.analysis += clock.wall_time();
  }



  const std::vector<int> &
  SparseContactSystem::ordering() const
  {
    return implementation->order;
  }



  SparseContactSystem::~SparseContactSystem() = default;



  void
  SparseContactSystem::set_rhs(const Vector<double> &rhs)
  {
    implementation->rhs         = &rhs;
    implementation->base_solved = false;
  }



  void
  SparseContactSystem::set_springs(const std::vector<Spring> &springs)
  {
    // New stiffnesses or directions are a new matrix: the next solve
    // starts from the factor of the old one (solve()); new gaps are a new
    // load only.
    Implementation &d = *implementation;
    d.springs         = springs::on_dofs(springs, d.pairs);
    d.base_solved     = false;
    ++d.n_spring_sets;
  }



  void
  SparseContactSystem::set_bound_couplings(
    const std::vector<BoundCoupling> &couplings)
  {
    implementation->couplings = couplings;
  }



  void
  SparseContactSystem::gaps_changed()
  {
    Implementation &d = *implementation;
    if (d.has_factor)
      ActiveSetSolver::make_constraints(d.base,
                                        d.pairs,
                                        d.base_active,
                                        d.constraints);
    d.base_solved = false;
  }



  void
  SparseContactSystem::solve(const std::vector<bool> &active,
                             std::vector<double>     &excess,
                             std::vector<double>     &lambda)
  {
    Implementation &d = *implementation;
    Assert(d.rhs != nullptr, ExcMessage("set_rhs() was not called"));

    // Why by hand: an active set that differs from the factor's A0 in m
    // rows is solved exactly on A0's factor by a bordered system (no
    // library updates a supernodal factor): the space of A is the space of
    // A0 plus one direction delta_r per released row r, with the added rows
    // a_p^T x = g_p as multiplier constraints. With x0 the solution on A0,
    // W = T K0^-1 T^T C D and V = T K0^-1 T^T B_N^T (one solve per row,
    // kept while A0 stays), x = x0 + (D - W) s - V mu, where
    //   [D^T C (D - W)   D^T B_N^T - D^T C V] [s ]   [D^T (f - C x0)]
    //   [B_N (D - W)     -B_N V             ] [mu] = [g_N - B_N x0  ].
    // It pays while an iteration's new solves cost less than a
    // factorisation; otherwise A becomes the new A0.
    std::vector<unsigned int> changed;
    unsigned int              n_new = 0;
    if (d.has_factor)
      for (unsigned int p = 0; p < d.pairs.size(); ++p)
        if (active[p] != d.base_active[p])
          {
            changed.push_back(p);
            n_new += d.corrections.count(p) == 0;
          }
    // A correction costs one solve with the factor and its set-up, about
    // 16 nnz(L) flops of the factorisation's rate (measured at 4.5e5 dofs:
    // 0.14 s against 3.5 s for a factorisation of 15.6 Gflop with
    // nnz(L) = 4e7); an update iteration one more solve (the refinement).
    // The corrections already made are paid for; the new ones are weighed
    // against a factorisation, and their vectors (n doubles each) may take
    // at most the factor's memory.
    const double correction_flops = 16 * d.cholesky.nnz_factor();
    const double vector_MB        = 8. * d.matrix.m() / 1048576.;
    // With other springs than the factor's, only the factor's own active
    // set is solved on it (by CG, solve_on_factor()); the bordered
    // update needs exact solves.
    const auto stale = [&]() {
      return !springs::same_matrix(d.springs, d.factor_springs);
    };
    // The multipliers (those of the coupled system with couplings) and
    // the excess of the solution.
    const auto report = [&](const RowMultipliers *coupled) {
      Timer clock;
      ActiveSetSolver::excess_and_multipliers(residual_of(d.matrix),
                                              *d.rhs,
                                              d.x,
                                              d.base,
                                              d.pairs,
                                              active,
                                              excess,
                                              lambda,
                                              d.springs,
                                              coupled);
      d.solves += clock.wall_time();
    };
    if (!d.couplings.empty())
      {
        // The coupled system: on a factor of this very set (its springs
        // may be older: the factor only preconditions).
        if (!d.has_factor || active != d.base_active)
          d.factorise(active);
        const RowMultipliers coupling(d.base, d.pairs, active, d.couplings);
        Timer                clock;
        const auto           b = springs::condensed_load(d.springs,
                                               residual_of(d.matrix),
                                               *d.rhs,
                                               d.constraints,
                                               [&](Vector<double> &r) {
                                                 coupling.project(r);
                                               });
        // From the factor's solution; within what half a factorisation
        // costs (as with stale springs alone), else on a factor of the
        // springs set now.
        Vector<double> y(b.size());
        const auto     start = [&]() {
          std::vector<double> z(b.begin(), b.end());
          d.factor().solve(z);
          std::copy(z.begin(), z.end(), y.begin());
        };
        start();
        if (!d.solve_on_factor(b, y, &coupling, d.krylov_budget()))
          {
            if (stale())
              d.factorise(active);
            start();
            AssertThrow(d.solve_on_factor(b, y, &coupling, 1000),
                        ExcMessage("the sparse path's GMRES on the coupled "
                                   "Coulomb bound did not converge in 1000 "
                                   "iterations"));
          }
        d.x = y;
        d.constraints.distribute(d.x);
        // (The next uncoupled solve makes its base solution anew.)
        d.base_solved = false;
        d.solves += clock.wall_time();
        report(&coupling);
        return;
      }
    if (!d.has_factor || (n_new + 1) * correction_flops > d.cholesky.flops() ||
        (d.corrections.size() + n_new) * vector_MB >
          std::max(d.factor().memory_MB(), 8 * vector_MB) ||
        changed.size() > 500 || (!changed.empty() && stale()))
      {
        d.factorise(active);
        changed.clear();
      }

    Timer      clock;
    const auto solve_base = [&]() {
      if (d.base_solved)
        return;
      const auto b      = springs::condensed_load(d.springs,
                                             residual_of(d.matrix),
                                             *d.rhs,
                                             d.constraints);
      bool       solved = false;
      if (stale())
        {
          // From the last solution's free part.
          Vector<double> y(b.size());
          if (d.x0.size() == b.size())
            {
              y = d.x0;
              for (const auto &line : d.constraints.get_lines())
                y(line.index) = 0;
            }
          solved = d.solve_on_factor(b, y, nullptr, d.krylov_budget());
          if (solved)
            d.x0 = y;
          else
            d.factorise(active);
        }
      if (!solved)
        {
          std::vector<double> z(b.begin(), b.end());
          d.factor().solve(z);
          d.x0.reinit(z.size());
          std::copy(z.begin(), z.end(), d.x0.begin());
        }
      d.constraints.distribute(d.x0);
      d.residual0.reinit(b.size());
      d.residual(d.residual0, d.x0);
      d.base_solved = true;
      ++d.n_solves;
    };
    solve_base();
    d.solves += clock.wall_time();

    d.x = d.x0;
    Vector<double> residual_of_x(d.x.size());
    if (!changed.empty())
      {
        clock.restart();
        for (const unsigned int p : changed)
          if (d.corrections.count(p) == 0)
            d.corrections.emplace(p, d.make_correction(p));
        const std::size_t   m = changed.size();
        std::vector<double> bordered(m * m); // column-major
        for (std::size_t i = 0; i < m; ++i)
          {
            const auto &ci = d.corrections.at(changed[i]);
            for (std::size_t j = 0; j < m; ++j)
              {
                const auto &cj = d.corrections.at(changed[j]);
                double      entry;
                if (ci.released)
                  entry = cj.released ? dot(ci.cv, cj.v) - dot(ci.cv, cj.w)
                                      : dot(ci.v, cj.v) - dot(ci.cv, cj.w);
                else
                  entry = cj.released ? dot(ci.v, cj.v) - dot(ci.v, cj.w)
                                      : -dot(ci.v, cj.w);
                bordered[j * m + i] = entry;
              }
          }
        const types::blas_int        n = m, one = 1;
        types::blas_int              info = 0;
        std::vector<types::blas_int> pivots(m);
        getrf(&n, &n, bordered.data(), &n, pivots.data(), &info);
        if (info != 0)
          {
            // A bordered system singular in floating point (rows dependent
            // to round-off): the exact path, a factorisation of A.
            d.factorise(active);
            solve_base();
            d.x = d.x0;
            changed.clear();
          }
        else
          {
            // x = x0 + (D - W) s - V mu, then one step of iterative refinement
            // with the same bordered solve on the residual: rows that are
            // nearly dependent (an added row beside a released one at the same
            // slave vertex) cost the first solve digits (measured on
            // knee_small: 4e-9 relative against a fresh factorisation, 3e-12
            // after the step, the cost of one more solve with the factor).
            Vector<double> r = d.residual0, dx0(r.size());
            for (unsigned int step = 0; step < 2; ++step)
              {
                // Base part: T K0^-1 T^T r (zero on the first step, where x0
                // is the base solution).
                dx0 = 0;
                if (step > 0)
                  {
                    dx0 = r;
                    d.solve_base_homogeneous(dx0);
                    d.vmult(r, dx0);
                    r.sadd(-1., 1., residual_of_x);
                  }
                std::vector<double> z(m);
                for (std::size_t i = 0; i < m; ++i)
                  {
                    const auto &c = d.corrections.at(changed[i]);
                    z[i]          = c.released ? dot(c.v, r)
                                               : d.pairs[changed[i]].reduced_gap -
                                          dot(c.v, d.x) - dot(c.v, dx0);
                  }
                getrs("N",
                      &n,
                      &one,
                      bordered.data(),
                      &n,
                      pivots.data(),
                      z.data(),
                      &n,
                      &info);
                AssertThrow(info == 0, ExcInternalError());
                d.x += dx0;
                for (std::size_t i = 0; i < m; ++i)
                  {
                    const auto &c = d.corrections.at(changed[i]);
                    d.x.add(-z[i], c.w);
                    if (c.released)
                      for (const auto &[dof, value] : c.v)
                        d.x(dof) += z[i] * value;
                  }
                d.residual(residual_of_x, d.x);
                r = residual_of_x;
              }
          }
        d.updates += clock.wall_time();
        ++d.n_updates;
        ++d.n_updates_on_factor;
      }

    report(nullptr);
  }



  double
  SparseContactSystem::displacement_scale() const
  {
    return ActiveSetSolver::displacement_scale(implementation->pairs,
                                               implementation->x);
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
    const Implementation         &d       = *implementation;
    std::map<std::string, double> figures = d.factor().statistics();
    figures.insert({{"ordering", d.ordering},
                    {"analysis", d.analysis},
                    {"factorisation", d.factorisation},
                    {"factorisations", d.n_factorisations},
                    {"solves", d.n_solves},
                    {"bordered_updates", d.n_updates},
                    {"update_solves", d.n_corrections},
                    {"update_time", d.updates},
                    {"solve_and_multipliers", d.solves},
                    {"factor_memory_MB", d.factor().memory_MB()},
                    {"factor_flops", d.cholesky.flops()},
                    {"factor_entries", d.cholesky.nnz_factor()},
                    {"spring_sets", d.n_spring_sets},
                    {"stale_factor_solves", d.n_stale_factor_solves},
                    {"stale_factor_cg_iterations", d.stale_factor_iterations},
                    {"stale_factor_time", d.stale_factor_time},
                    {"coupled_solves", d.n_coupled_solves},
                    {"coupled_gmres_iterations", d.coupled_iterations},
                    {"coupled_time", d.coupled_time}});
    return figures;
  }
} // namespace knee_contact
