#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/sparse_cholesky.h>

#include <deal.II/base/timer.h>

#include <deal.II/lac/lapack_templates.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <new>
#include <set>
#include <stdexcept>

namespace knee_contact
{
  using sparse_cholesky::SparseCholesky;

  namespace
  {
    /** C = A A^T - shift I for a dense lower-triangular A (k x k). */
    std::vector<double>
    product_with_transpose(const std::vector<double> &a,
                           const std::size_t          k,
                           const double               shift)
    {
      std::vector<double> c(k * k, 0.);
      if (k == 0)
        return c;
      const types::blas_int n   = k;
      const double          one = 1, zero = 0;
      syrk("L", "N", &n, &n, &one, a.data(), &n, &zero, c.data(), &n);
      for (std::size_t j = 0; j < k; ++j)
        {
          c[j * k + j] -= shift;
          for (std::size_t i = j + 1; i < k; ++i)
            c[i * k + j] = c[j * k + i];
        }
      return c;
    }
  } // namespace



  class CondensedContactSystem::Implementation
  {
  public:
    const SparseMatrix<double>      &matrix;
    const AffineConstraints<double> &base;
    const std::vector<ContactRow>   &pairs;

    /** Contact unknowns: global dof of each local index, and back. */
    std::vector<types::global_dof_index>                  dofs;
    std::map<types::global_dof_index, unsigned int>       local_of;
    std::vector<std::vector<std::pair<unsigned, double>>> rows; // per pair
    std::vector<int>                                      order;
    SparseCholesky                                        cholesky;
    double                                                shift = 0;
    std::vector<double> l_cc;    // trailing block of L, column-major
    std::vector<double> s;       // Schur complement, k x k, symmetric
    std::vector<double> forward; // L^-1 P b of the current load case
    std::vector<double> f;       // condensed right hand side
    std::vector<double> x_c;     // contact unknowns of the last solve
    Timings             timings;

    /**
     * The loop in multiplier space (set_up_multiplier_loop()): the pairs
     * with a row (q = 0..P-1), rho, the Cholesky factor of
     * S~ = S + rho B^T B (B: every pair's row), W = S~^-1 B^T (k x P),
     * G = B W (P x P), and per load case u0 = S~^-1 f and h = B u0.
     */
    bool multiplier_loop = false;
    /** Whether the measured-only rows join it (once springs are set). */
    bool                               measured_in_loop = false;
    std::vector<ContactSystem::Spring> springs;
    std::vector<unsigned int>          row_pairs;
    double                             rho = 0;
    std::vector<double>                s_tilde;
    std::vector<double>                w;
    std::vector<double>                g;
    std::vector<double>                u0;
    std::vector<double>                h;
    /** Position q of each pair's row in the loop, -1 for none. */
    std::vector<int> q_of;
    /**
     * Whether the stick rows are among S~'s rows (else each is in an
     * iteration's system only while active).
     */
    bool stick_rows_in_tilde = true;

    /** Whether loop row q is one of S~'s. */
    bool
    in_tilde(const std::size_t q) const
    {
      return stick_rows_in_tilde || !pairs[row_pairs[q]].stick;
    }

    /**
     * The Coulomb couplings of the following solves, and the lambda_n of
     * each in the last solve (for the multipliers' residual, and as a
     * fixed load where the loop's LU fails).
     */
    std::vector<ContactSystem::BoundCoupling> couplings;
    std::vector<double>                       coupling_lambda;
    /** Solves the multiplier loop took with couplings. */
    unsigned int n_coupled_solves = 0;
    /** The multipliers of the last solve. */
    std::vector<double> last_lambda;
    /**
     * Coupled rows outside the loop (the tangential rows in 2D): their
     * S~^-1 b_r (k each) and B S~^-1 b_r (P each), made on first use.
     */
    std::map<unsigned int, unsigned int> outside_of;
    std::vector<double>                  w_outside, g_outside;

    void
    set_up_multiplier_loop();

    /** S~^-1 b_r and B S~^-1 b_r of a coupled row r. */
    std::pair<const double *, const double *>
    columns_of(const unsigned int r) const;

    /** Adds the columns of the couplings' rows not yet at hand. */
    void
    add_outside_columns();

    /** u0 = S~^-1 f and h = B u0 of the current load case. */
    void
    load_multiplier_loop();

    /** A spring's w over the contact unknowns and its g_w. */
    std::pair<std::vector<std::pair<unsigned int, double>>, double>
    spring_row(const ContactSystem::Spring &spring) const;

    bool
    solve_by_multipliers(const std::vector<bool> &active);

    void
    solve_by_elimination(const std::vector<bool> &active);

    Implementation(const SparseMatrix<double>      &matrix,
                   const AffineConstraints<double> &base,
                   const std::vector<ContactRow>   &pairs)
      : matrix(matrix)
      , base(base)
      , pairs(pairs)
    {}
  };



  CondensedContactSystem::CondensedContactSystem(
    const SparseMatrix<double>      &matrix,
    const AffineConstraints<double> &base,
    const std::vector<ContactRow>   &pairs,
    const std::vector<int>          &order)
    : implementation(std::make_unique<Implementation>(matrix, base, pairs))
  {
    Implementation &d = *implementation;
    // Every free dof of an active-capable row is a contact unknown, in
    // ascending order (deterministic).
    std::set<types::global_dof_index> contact;
    for (const auto &pair : pairs)
      if (pair.eliminated != numbers::invalid_dof_index)
        for (const auto &entry : pair.reduced_row)
          contact.insert(entry.first);
    d.dofs.assign(contact.begin(), contact.end());
    for (unsigned int l = 0; l < d.dofs.size(); ++l)
      d.local_of[d.dofs[l]] = l;
    d.rows.resize(pairs.size());
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (pairs[p].eliminated != numbers::invalid_dof_index)
        for (const auto &[dof, a] : pairs[p].reduced_row)
          d.rows[p].emplace_back(d.local_of.at(dof), a);

    Timer      clock;
    const auto a = sparse_cholesky::condense(matrix, base);
    if (order.empty())
      d.order = sparse_cholesky::fill_reducing_ordering(a, d.dofs);
    else
      {
        d.order.reserve(order.size());
        for (const int i : order)
          if (d.local_of.find(i) == d.local_of.end())
            d.order.push_back(i);
        d.order.insert(d.order.end(), d.dofs.begin(), d.dofs.end());
      }
    d.timings.ordering = clock.wall_time();

    clock.restart();
    // The shift only needs to make the trailing block positive definite:
    // the largest diagonal entry does, and keeps S = L L^T - shift I at
    // the round-off of C.
    for (std::size_t i = 0; i + 1 < a.row_start.size(); ++i)
      for (std::size_t k = a.row_start[i]; k < a.row_start[i + 1]; ++k)
        if (a.column[k] == i)
          d.shift = std::max(d.shift, std::abs(a.value[k]));
    // CHOLMOD's postordering merges supernodes (measured 2x faster
    // factorisations) but would move the contact unknowns of separate
    // bodies apart; so the interior C_ii alone is analysed with it, and its
    // postordered order, with the contact unknowns after it, is given to
    // the analysis of the whole matrix (the elimination tree of the leading
    // block is C_ii's).
    {
      const std::size_t n = a.size(), n_interior = n - d.dofs.size();
      std::vector<int>  compact(n, -1);
      for (std::size_t i = 0; i < n_interior; ++i)
        compact[d.order[i]] = i;
      sparse_cholesky::CsrMatrix interior;
      interior.row_start.assign(1, 0);
      for (std::size_t i = 0; i < n_interior; ++i)
        {
          const auto row = d.order[i];
          for (std::size_t e = a.row_start[row]; e < a.row_start[row + 1]; ++e)
            if (compact[a.column[e]] >= 0)
              {
                interior.column.push_back(compact[a.column[e]]);
                interior.value.push_back(0.);
              }
          interior.row_start.push_back(interior.column.size());
        }
      std::vector<int> identity(n_interior);
      for (std::size_t i = 0; i < n_interior; ++i)
        identity[i] = i;
      sparse_cholesky::SparseCholesky postorder;
      postorder.analyse(interior, identity, true);
      const auto       final_interior = postorder.final_last(n_interior);
      std::vector<int> order(d.order);
      for (std::size_t i = 0; i < n_interior; ++i)
        d.order[i] = order[final_interior[i]];
    }
    d.cholesky.analyse(a, d.order, false);
    if (!d.cholesky.factorise(a, d.dofs.size(), d.shift))
      AssertThrow(false, ExcNotPositiveDefinite());
    d.cholesky.release_matrix();
    d.timings.factorisation = clock.wall_time();

    clock.restart();
    const std::size_t k = d.dofs.size();
    d.l_cc              = d.cholesky.trailing_block(k);
    d.s                 = product_with_transpose(d.l_cc, k, d.shift);
    d.timings.schur     = clock.wall_time();

    clock.restart();
    d.set_up_multiplier_loop();
    // The multiplier loop needs only S~'s factor, W and G; the elimination
    // path makes S again from L_cc if it is ever needed.
    if (d.multiplier_loop)
      std::vector<double>().swap(d.s);
    d.timings.loop_setup = clock.wall_time();
  }



  void
  CondensedContactSystem::Implementation::set_up_multiplier_loop()
  {
    // Why by hand: the loop needs the KKT system of S with the active rows
    // for a new active set in every iteration, at less than one dense
    // factorisation each. With S~ = S + rho B^T B over the rows of all P
    // pairs, S = S~ - rho B_A^T B_A - rho B_I^T B_I, and the KKT system
    //   S x + B_A^T lambda = f,  B_A x = g_A
    // becomes, with z_A = lambda - rho g_A and z_I = -rho (B_I x),
    //   x = S~^-1 f - W z,  (G - D_I / rho) z = h - g_A,
    // W = S~^-1 B^T, G = B W, h = B S~^-1 f, D_I the inactive diagonal.
    // A row left out of S~ (a stick row, below) is in an iteration's system
    // only while active, with z = lambda and the equation of an active row,
    // (G z)_q = h_q - g_q.
    // S~ and W are made once per mesh (S~ is regular even where S is not:
    // a body held only by contact is held by the rows of all pairs), each
    // iteration solves a P x P system (P = number of pairs, a fraction of
    // k), and each load case costs two triangular solves with S~.
    const std::size_t k = dofs.size();
    // Rows that are only measured (the tangential rows with friction) stay
    // out: they are never active, and each row here adds to the P x P
    // system of every iteration.
    row_pairs.clear();
    outside_of.clear();
    w_outside.clear();
    g_outside.clear();
    q_of.assign(pairs.size(), -1);
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (pairs[p].eliminated != numbers::invalid_dof_index &&
          (!pairs[p].measured_only || measured_in_loop))
        {
          q_of[p] = row_pairs.size();
          row_pairs.push_back(p);
        }
    const std::size_t n_rows = row_pairs.size();
    if (k == 0 || n_rows == 0)
      return;
    double s_max = 0, a_max = 0;
    for (std::size_t i = 0; i < k; ++i)
      s_max = std::max(s_max, s[i * k + i]);
    for (const unsigned int p : row_pairs)
      {
        double norm = 0;
        for (const auto &[l, a] : rows[p])
          norm += a * a;
        a_max = std::max(a_max, norm);
      }
    if (!(s_max > 0 && a_max > 0))
      return;
    rho = s_max / a_max;
    // With friction the stick rows (3 n of the 4 n rows in 2D) stay out of
    // S~ where S~ is regular without them: an inactive row of S~ is an
    // unknown of every iteration's system, a stick row outside it only
    // while it is active (2D knee, 290 pairs, gait path: P = 870 rows
    // against the 290 normal rows and the few sticking pairs' rows). A body
    // that only friction holds tangentially needs them in S~.
    const types::blas_int n         = k;
    types::blas_int       info      = 0;
    const auto            factorise = [&](const bool with_stick_rows) {
      stick_rows_in_tilde = with_stick_rows;
      s_tilde             = s;
      for (std::size_t q = 0; q < n_rows; ++q)
        if (in_tilde(q))
          {
            for (const auto &[i, a_i] : rows[row_pairs[q]])
              for (const auto &[j, a_j] : rows[row_pairs[q]])
                s_tilde[std::size_t(j) * k + i] += rho * a_i * a_j;
          }
      potrf("L", &n, s_tilde.data(), &n, &info);
      if (info != 0)
        return false;
      // A pivot at round-off of the largest diagonal entry: S~ is singular
      // in all but round-off (a body free even with every pair closed);
      // the elimination path and the rigid-mode diagnostics handle that.
      double pivot_min = std::numeric_limits<double>::max();
      for (std::size_t i = 0; i < k; ++i)
        pivot_min =
          std::min(pivot_min, s_tilde[i * k + i] * s_tilde[i * k + i]);
      return pivot_min >= 1e-10 * (s_max + rho * a_max);
    };
    const bool has_stick_rows =
      std::any_of(row_pairs.begin(), row_pairs.end(), [&](const unsigned p) {
        return pairs[p].stick;
      });
    if (!(has_stick_rows && factorise(false)) && !factorise(true))
      return;

    w.assign(k * n_rows, 0.);
    for (std::size_t q = 0; q < n_rows; ++q)
      for (const auto &[l, a] : rows[row_pairs[q]])
        w[q * k + l] += a;
    const types::blas_int n_rhs = n_rows;
    potrs("L", &n, &n_rhs, s_tilde.data(), &n, w.data(), &n, &info);
    AssertThrow(info == 0, ExcInternalError());
    g.assign(n_rows * n_rows, 0.);
    for (std::size_t c = 0; c < n_rows; ++c)
      for (std::size_t q = 0; q < n_rows; ++q)
        {
          double sum = 0;
          for (const auto &[l, a] : rows[row_pairs[q]])
            sum += a * w[c * k + l];
          g[c * n_rows + q] = sum;
        }
    multiplier_loop = true;
  }



  std::pair<const double *, const double *>
  CondensedContactSystem::Implementation::columns_of(const unsigned int r) const
  {
    const std::size_t k = dofs.size(), n_rows = row_pairs.size();
    if (q_of[r] >= 0)
      return {&w[q_of[r] * k], &g[q_of[r] * n_rows]};
    const unsigned int e = outside_of.at(r);
    return {&w_outside[e * k], &g_outside[e * n_rows]};
  }



  void
  CondensedContactSystem::Implementation::add_outside_columns()
  {
    std::vector<unsigned int> added;
    for (const auto &coupling : couplings)
      for (const auto &[r, c] : coupling.rows)
        if (q_of[r] < 0 && outside_of.count(r) == 0)
          {
            outside_of[r] = outside_of.size();
            added.push_back(r);
          }
    if (added.empty())
      return;
    const std::size_t   k = dofs.size(), n_rows = row_pairs.size();
    std::vector<double> w_new(k * added.size(), 0.);
    for (std::size_t e = 0; e < added.size(); ++e)
      for (const auto &[l, a] : rows[added[e]])
        w_new[e * k + l] += a;
    const types::blas_int n = k, n_rhs = added.size();
    types::blas_int       info = 0;
    potrs("L", &n, &n_rhs, s_tilde.data(), &n, w_new.data(), &n, &info);
    AssertThrow(info == 0, ExcInternalError());
    for (std::size_t e = 0; e < added.size(); ++e)
      for (std::size_t q = 0; q < n_rows; ++q)
        {
          double sum = 0;
          for (const auto &[l, a] : rows[row_pairs[q]])
            sum += a * w_new[e * k + l];
          g_outside.push_back(sum);
        }
    w_outside.insert(w_outside.end(), w_new.begin(), w_new.end());
  }



  bool
  CondensedContactSystem::Implementation::solve_by_multipliers(
    const std::vector<bool> &active)
  {
    const std::size_t k = dofs.size(), n_rows = row_pairs.size();
    // A coupling's load -lambda_n sum_r c_r b_r, lambda_n = z_n + rho g_n,
    // changes B x = h - G z into h - rho g_n v - (G z + v z_n) with
    // v = sum_r c_r B S~^-1 b_r: a column added to G, a change of h; every
    // row's equation below is then written as before on G' and h' (G' is
    // read through g_of(): only the added columns are stored).
    std::vector<double>              h = this->h;
    std::vector<int>                 added_at(n_rows, -1);
    std::vector<std::vector<double>> added;
    for (const auto &coupling : couplings)
      {
        const int    q_n = q_of[coupling.normal_row];
        const double gap = pairs[coupling.normal_row].reduced_gap;
        AssertThrow(q_n >= 0 && active[coupling.normal_row] &&
                      added_at[q_n] < 0,
                    ExcInternalError());
        added_at[q_n] = added.size();
        added.emplace_back(n_rows, 0.);
        std::vector<double> &v = added.back();
        for (const auto &[r, c] : coupling.rows)
          {
            const double *g_r = columns_of(r).second;
            for (std::size_t q = 0; q < n_rows; ++q)
              v[q] += c * g_r[q];
          }
        for (std::size_t q = 0; q < n_rows; ++q)
          h[q] -= rho * gap * v[q];
      }
    // G'(row, column) of the loop rows.
    const auto g_of = [&](const std::size_t row, const std::size_t column) {
      const double entry = g[column * n_rows + row];
      return added_at[column] < 0 ? entry
                                  : entry + added[added_at[column]][row];
    };
    // This iteration's system: the rows of S~ (active or not) and the stick
    // rows that are active; position of each loop row in it, -1 for none.
    std::vector<unsigned int> selected;
    std::vector<int>          at(n_rows, -1);
    for (std::size_t q = 0; q < n_rows; ++q)
      if (in_tilde(q) || active[row_pairs[q]])
        {
          at[q] = selected.size();
          selected.push_back(q);
        }
    const std::size_t   n_system = selected.size();
    std::vector<double> m(n_system * n_system), z(n_system);
    for (std::size_t b = 0; b < n_system; ++b)
      for (std::size_t a = 0; a < n_system; ++a)
        m[b * n_system + a] = g_of(selected[a], selected[b]);
    for (std::size_t a = 0; a < n_system; ++a)
      {
        const unsigned int q = selected[a], p = row_pairs[q];
        if (active[p])
          z[a] = h[q] - pairs[p].reduced_gap;
        else
          {
            z[a] = h[q];
            m[a * n_system + a] -= 1. / rho;
          }
      }
    // A spring k on w = sum_i c_i b_i (rows never active): their z_i must
    // give -rho b_i x + k c_i (w x - g_w), so with M = I - k/rho c c^T
    // over its rows, M (G z)_i - z_i / rho = M h_i + k/rho g_w c_i (an
    // inactive row's equation where k = 0, scaled alike: rows scaled by
    // rho cost the LU digits, 1e-9 of the forces on a sliding block).
    for (const auto &spring : springs)
      {
        double g_w = 0;
        for (const auto &[r, c] : spring.rows)
          {
            AssertThrow(q_of[r] >= 0 && at[q_of[r]] >= 0 && !active[r],
                        ExcInternalError());
            g_w += c * pairs[r].reduced_gap;
          }
        for (const auto &[r_i, c_i] : spring.rows)
          {
            const std::size_t a_i = at[q_of[r_i]];
            for (std::size_t column = 0; column < n_system; ++column)
              {
                double sum = 0;
                for (const auto &[r_j, c_j] : spring.rows)
                  sum += ((r_i == r_j ? 1. : 0.) -
                          spring.stiffness / rho * c_i * c_j) *
                         g_of(q_of[r_j], selected[column]);
                m[column * n_system + a_i] = sum;
              }
            m[a_i * n_system + a_i] -= 1. / rho;
            double right = spring.stiffness / rho * g_w * c_i;
            for (const auto &[r_j, c_j] : spring.rows)
              right +=
                ((r_i == r_j ? 1. : 0.) - spring.stiffness / rho * c_i * c_j) *
                h[q_of[r_j]];
            z[a_i] = right;
          }
      }
    const types::blas_int        n = n_system, one = 1;
    types::blas_int              info = 0;
    std::vector<types::blas_int> pivots(n_system);
    getrf(&n, &n, m.data(), &n, pivots.data(), &info);
    if (info != 0)
      return false;
    getrs("N", &n, &one, m.data(), &n, pivots.data(), z.data(), &n, &info);
    AssertThrow(info == 0, ExcInternalError());
    x_c = u0;
    for (std::size_t a = 0; a < n_system; ++a)
      {
        const double *w_q = &w[selected[a] * k];
        for (std::size_t l = 0; l < k; ++l)
          x_c[l] -= z[a] * w_q[l];
      }
    coupling_lambda.assign(couplings.size(), 0.);
    n_coupled_solves += !couplings.empty();
    for (std::size_t i = 0; i < couplings.size(); ++i)
      {
        const unsigned int normal = couplings[i].normal_row;
        AssertThrow(in_tilde(q_of[normal]), ExcInternalError());
        coupling_lambda[i] =
          z[at[q_of[normal]]] + rho * pairs[normal].reduced_gap;
        for (const auto &[r, c] : couplings[i].rows)
          {
            const double *w_r = columns_of(r).first;
            for (std::size_t l = 0; l < k; ++l)
              x_c[l] -= coupling_lambda[i] * c * w_r[l];
          }
      }
    return true;
  }



  CondensedContactSystem::~CondensedContactSystem() = default;



  unsigned int
  CondensedContactSystem::n_contact_unknowns() const
  {
    return implementation->dofs.size();
  }



  std::pair<double, double>
  CondensedContactSystem::memory_MB() const
  {
    const Implementation &d = *implementation;
    const double          dense =
      (d.l_cc.size() + d.s.size() + d.s_tilde.size() + d.w.size() + d.g.size() +
       d.w_outside.size() + d.g_outside.size()) *
      sizeof(double) / 1048576.;
    return {d.cholesky.memory_MB(), dense};
  }



  std::map<std::string, double>
  CondensedContactSystem::statistics() const
  {
    const Timings &t                 = implementation->timings;
    const auto [factor_MB, dense_MB] = memory_MB();
    return {{"contact_unknowns", n_contact_unknowns()},
            {"ordering", t.ordering},
            {"factorisation", t.factorisation},
            {"schur_complement", t.schur},
            {"loop_setup", t.loop_setup},
            {"factor_memory_MB", factor_MB},
            {"dense_memory_MB", dense_MB},
            {"condensation", t.condensation},
            {"active_set_loop", t.dense},
            {"expansion", t.expansion},
            {"coupled_solves", implementation->n_coupled_solves}};
  }



  void
  CondensedContactSystem::set_rhs(const Vector<double> &rhs)
  {
    Implementation &d = *implementation;
    Timer           clock;
    const auto      b =
      sparse_cholesky::condense(residual_of(d.matrix), rhs, d.base);
    // y = L^-1 P b; with L = [L_ii 0; L_ci L_cc], f = b_c - C_ci C_ii^-1 b_i
    // = L_cc y_c.
    d.forward.assign(b.begin(), b.end());
    d.cholesky.solve(CHOLMOD_P, d.forward);
    d.cholesky.solve(CHOLMOD_L, d.forward);
    const std::size_t k = d.dofs.size(), n = d.forward.size();
    d.f.assign(k, 0.);
    for (std::size_t j = 0; j < k; ++j)
      for (std::size_t i = j; i < k; ++i)
        d.f[i] += d.l_cc[j * k + i] * d.forward[n - k + j];
    d.load_multiplier_loop();
    d.timings.condensation += clock.wall_time();
  }



  void
  CondensedContactSystem::Implementation::load_multiplier_loop()
  {
    if (!multiplier_loop)
      return;
    const std::size_t k       = dofs.size();
    u0                        = f;
    const types::blas_int n_k = k, one = 1;
    types::blas_int       info = 0;
    potrs("L", &n_k, &one, s_tilde.data(), &n_k, u0.data(), &n_k, &info);
    AssertThrow(info == 0, ExcInternalError());
    h.assign(row_pairs.size(), 0.);
    for (std::size_t q = 0; q < row_pairs.size(); ++q)
      for (const auto &[l, a] : rows[row_pairs[q]])
        h[q] += a * u0[l];
  }



  std::pair<std::vector<std::pair<unsigned int, double>>, double>
  CondensedContactSystem::Implementation::spring_row(
    const ContactSystem::Spring &spring) const
  {
    std::map<unsigned int, double> w;
    double                         gap = 0;
    for (const auto &[r, c] : spring.rows)
      {
        for (const auto &[l, a] : rows[r])
          w[l] += c * a;
        gap += c * pairs[r].reduced_gap;
      }
    return {{w.begin(), w.end()}, gap};
  }



  void
  CondensedContactSystem::set_springs(const std::vector<Spring> &springs)
  {
    Implementation &d = *implementation;
    d.springs         = springs;
    // The first springs: their rows (measured only so far) join the
    // multiplier loop, set up again on S.
    if (!springs.empty() && d.multiplier_loop && !d.measured_in_loop)
      {
        Timer clock;
        d.measured_in_loop = true;
        d.multiplier_loop  = false;
        d.s = product_with_transpose(d.l_cc, d.dofs.size(), d.shift);
        d.set_up_multiplier_loop();
        if (d.multiplier_loop)
          std::vector<double>().swap(d.s);
        d.load_multiplier_loop();
        if (d.multiplier_loop)
          d.add_outside_columns();
        d.timings.loop_setup += clock.wall_time();
      }
  }



  bool
  CondensedContactSystem::takes_bound_couplings() const
  {
    return implementation->multiplier_loop;
  }



  void
  CondensedContactSystem::set_bound_couplings(
    const std::vector<BoundCoupling> &couplings)
  {
    Implementation &d = *implementation;
    d.couplings       = couplings;
    if (d.multiplier_loop)
      {
        Timer clock;
        d.add_outside_columns();
        d.timings.loop_setup += clock.wall_time();
      }
  }



  void
  CondensedContactSystem::Implementation::solve_by_elimination(
    const std::vector<bool> &active)
  {
    Implementation   &d = *this;
    const std::size_t k = d.dofs.size();
    if (s.empty())
      s = product_with_transpose(l_cc, k, shift);
    // The springs' k w w^T on S and k g_w w on f, for this solve; the
    // couplings as loads, with the lambda_n of the last solve (this
    // symmetric path cannot take them implicitly: a fixed-point step).
    std::vector<double> s_saved, f_saved;
    if (!springs.empty() || !couplings.empty())
      {
        s_saved = s;
        f_saved = f;
        coupling_lambda.assign(couplings.size(), 0.);
        for (std::size_t i = 0; i < couplings.size(); ++i)
          {
            const unsigned int normal = couplings[i].normal_row;
            coupling_lambda[i] =
              last_lambda.empty() ? 0. : std::max(last_lambda[normal], 0.);
            for (const auto &[r, c] : couplings[i].rows)
              for (const auto &[l, a] : rows[r])
                f[l] -= coupling_lambda[i] * c * a;
          }
        for (const auto &spring : springs)
          {
            const auto [w, g_w] = spring_row(spring);
            for (const auto &[i, a_i] : w)
              {
                f[i] += spring.stiffness * g_w * a_i;
                for (const auto &[j, a_j] : w)
                  s[std::size_t(j) * k + i] += spring.stiffness * a_i * a_j;
              }
          }
      }
    // The active rows, each solved for its eliminated dof, as constraints
    // on the local indices; close() resolves chains (a row whose
    // eliminated dof another row refers to), as in the full path.
    AffineConstraints<double> lines;
    for (unsigned int p = 0; p < d.pairs.size(); ++p)
      if (active[p])
        {
          const unsigned int j   = d.local_of.at(d.pairs[p].eliminated);
          double             a_j = 0;
          for (const auto &[l, a] : d.rows[p])
            if (l == j)
              a_j = a;
          lines.add_line(j);
          for (const auto &[l, a] : d.rows[p])
            if (l != j)
              lines.add_entry(j, l, -a / a_j);
          lines.set_inhomogeneity(j, d.pairs[p].reduced_gap / a_j);
        }
    lines.close();

    // x_c = T y + t: column of each free local index, and T's entries per
    // local index.
    std::vector<int> free_index(k, -1);
    unsigned int     m = 0;
    for (unsigned int l = 0; l < k; ++l)
      if (!lines.is_constrained(l))
        free_index[l] = m++;
    std::vector<std::vector<std::pair<unsigned, double>>> t_of(k);
    std::vector<double>                                   t(k, 0.);
    for (unsigned int l = 0; l < k; ++l)
      if (free_index[l] >= 0)
        t_of[l].emplace_back(free_index[l], 1.);
      else
        {
          for (const auto &[i, c] : *lines.get_constraint_entries(l))
            t_of[l].emplace_back(free_index[i], c);
          t[l] = lines.get_inhomogeneity(l);
        }

    // R = T^T S T and r = T^T (f - S t); S T column by column (S is
    // symmetric, so its rows serve as columns).
    std::vector<double> st(std::size_t(k) * m, 0.);
    for (unsigned int j = 0; j < k; ++j)
      for (const auto &[b, c] : t_of[j])
        {
          const double *s_j = &d.s[j * k];
          double       *col = &st[std::size_t(b) * k];
          for (unsigned int i = 0; i < k; ++i)
            col[i] += c * s_j[i];
        }
    std::vector<double> f_st = d.f;
    for (unsigned int j = 0; j < k; ++j)
      if (t[j] != 0)
        for (unsigned int i = 0; i < k; ++i)
          f_st[i] -= d.s[j * k + i] * t[j];
    std::vector<double> reduced(std::size_t(m) * m, 0.); // column-major
    std::vector<double> y(m, 0.);
    for (unsigned int i = 0; i < k; ++i)
      for (const auto &[a, c] : t_of[i])
        {
          y[a] += c * f_st[i];
          for (unsigned int b = 0; b < m; ++b)
            reduced[std::size_t(b) * m + a] += c * st[std::size_t(b) * k + i];
        }
    if (m > 0)
      {
        const types::blas_int n = m, one = 1;
        types::blas_int       info = 0;
        potrf("L", &n, reduced.data(), &n, &info);
        AssertThrow(info == 0, ExcNotPositiveDefinite());
        potrs("L", &n, &one, reduced.data(), &n, y.data(), &n, &info);
        AssertThrow(info == 0, ExcInternalError());
      }
    d.x_c.assign(k, 0.);
    for (unsigned int l = 0; l < k; ++l)
      {
        d.x_c[l] = t[l];
        for (const auto &[a, c] : t_of[l])
          d.x_c[l] += c * y[a];
      }
    if (!springs.empty() || !couplings.empty())
      {
        s.swap(s_saved);
        f.swap(f_saved);
      }
  }



  void
  CondensedContactSystem::solve(const std::vector<bool> &active,
                                std::vector<double>     &excess,
                                std::vector<double>     &lambda)
  {
    Implementation   &d = *implementation;
    Timer             clock;
    const std::size_t k = d.dofs.size();
    if (!d.multiplier_loop || !d.solve_by_multipliers(active))
      d.solve_by_elimination(active);

    // Multipliers from the condensed residual r_c = f - S x_c, which is
    // A'^T lambda on the contact unknowns.
    // S x_c = L_cc (L_cc^T x_c) - shift x_c: S itself is not kept.
    std::vector<double> s_x = d.x_c;
    if (k > 0)
      {
        const types::blas_int n = k, one = 1;
        trmv("L", "T", "N", &n, d.l_cc.data(), &n, s_x.data(), &one);
        trmv("L", "N", "N", &n, d.l_cc.data(), &n, s_x.data(), &one);
      }
    Vector<double> residual(d.matrix.m());
    for (unsigned int i = 0; i < k; ++i)
      residual(d.dofs[i]) = d.f[i] - (s_x[i] - d.shift * d.x_c[i]);
    // Less the springs' forces k (w x - g_w) w.
    for (const auto &spring : d.springs)
      {
        const auto [w, g_w] = d.spring_row(spring);
        double stretch      = -g_w;
        for (const auto &[i, a] : w)
          stretch += a * d.x_c[i];
        for (const auto &[i, a] : w)
          residual(d.dofs[i]) -= spring.stiffness * stretch * a;
      }
    // Less the couplings' forces lambda_n c_r b_r.
    for (std::size_t i = 0; i < d.couplings.size(); ++i)
      for (const auto &[r, c] : d.couplings[i].rows)
        for (const auto &[l, a] : d.rows[r])
          residual(d.dofs[l]) -= d.coupling_lambda[i] * c * a;
    lambda = ActiveSetSolver::multipliers(residual,
                                          AffineConstraints<double>(),
                                          d.pairs,
                                          active);
    excess.assign(d.pairs.size(), 0.);
    for (unsigned int p = 0; p < d.pairs.size(); ++p)
      {
        excess[p] = -d.pairs[p].reduced_gap;
        for (const auto &[l, a] : d.rows[p])
          excess[p] += a * d.x_c[l];
      }
    d.last_lambda = lambda;
    d.timings.dense += clock.wall_time();
  }



  double
  CondensedContactSystem::displacement_scale() const
  {
    double scale = 0;
    for (const double x : implementation->x_c)
      scale = std::max(scale, std::abs(x));
    return scale;
  }



  void
  CondensedContactSystem::solution(Vector<double> &x)
  {
    Implementation   &d = *implementation;
    Timer             clock;
    const std::size_t k = d.dofs.size(), n = d.forward.size();
    // z = [y_i; L_cc^T x_c], then x = P^T L^-T z.
    std::vector<double> z = d.forward;
    for (std::size_t j = 0; j < k; ++j)
      {
        double sum = 0;
        for (std::size_t i = j; i < k; ++i)
          sum += d.l_cc[j * k + i] * d.x_c[i];
        z[n - k + j] = sum;
      }
    d.cholesky.solve(CHOLMOD_Lt, z);
    d.cholesky.solve(CHOLMOD_Pt, z);
    x.reinit(n);
    std::copy(z.begin(), z.end(), x.begin());
    for (std::size_t l = 0; l < k; ++l)
      x(d.dofs[l]) = d.x_c[l];
    d.base.distribute(x);
    d.timings.expansion += clock.wall_time();
  }



  double
  reference_solve(const SparseMatrix<double>      &matrix,
                  const Vector<double>            &rhs,
                  const AffineConstraints<double> &base,
                  const std::vector<ContactRow>   &pairs,
                  const std::vector<bool>         &active,
                  Vector<double>                  &x)
  {
    AffineConstraints<double> constraints;
    ActiveSetSolver::make_constraints(base, pairs, active, constraints);
    Timer      clock;
    const auto a = sparse_cholesky::condense(matrix, constraints);
    const auto b =
      sparse_cholesky::condense(residual_of(matrix), rhs, constraints);
    const auto     order = sparse_cholesky::fill_reducing_ordering(a, {});
    SparseCholesky cholesky;
    cholesky.analyse(a, order, true);
    AssertThrow(cholesky.factorise(a),
                ExcMessage("the reference system is not positive definite"));
    std::vector<double> z(b.begin(), b.end());
    cholesky.solve(CHOLMOD_A, z);
    const double time = clock.wall_time();
    x.reinit(z.size());
    std::copy(z.begin(), z.end(), x.begin());
    constraints.distribute(x);
    return time;
  }
} // namespace knee_contact
