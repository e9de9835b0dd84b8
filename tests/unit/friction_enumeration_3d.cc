// The active-set loop with Coulomb friction in 3D against an independent
// solution of the same discrete problem. Every state of the four pairs of
// qp_scene_friction_3d.prm (open, stick, slip: 3^4 = 81 combinations) is
// solved densely (LAPACK) in the dofs left free by Gamma_u:
//   open:  a_N x <= g_N                          (no force)
//   stick: a_N x = g_N, A_T x = g_T,             lambda_n >= 0,
//                                                |lambda_t| <= mu lambda_n
//   slip:  a_N x = g_N, lambda_t = mu lambda_n d, lambda_n >= 0,
//          d = s / |s|, s = A_T x - g_T != 0     (it slips the way the
//                                                friction force points)
// with C x - f + sum (a_N lambda_n + A_T^T lambda_t) = 0, A_T the pair's two
// tangential rows. A slipping pair's direction d = (cos theta, sin theta)
// is unknown: for fixed angles the state is a linear system (unsymmetric),
// and the angles are found by Newton's method on d x s = 0 (a
// finite-difference Jacobian of the few angles), from the direction of the
// tangential force the pair would need to stick and, failing that, from
// eight others. This is written from the conditions, not from the loop: it
// shares only the matrix, the load and the rows (N, T_1, T_2) with the
// program, not the stick rows, the springs of its Newton step, the bounds'
// fixed point or the solver paths. Asserted: exactly one state satisfies
// the conditions, the loop's statuses are that state, every status occurs,
// and x, lambda_n and lambda_t equal the reference to 1e-10 relative (the
// loop stops at a complementarity residual of 1e-12, its Contact/Tolerance
// here; measured 1.1e-14 and 6.4e-14 with node-to-segment rows, 9.4e-15
// and 4.6e-14 with mortar rows). Done for node-to-segment rows (mu = 1)
// and for mortar rows (mu = 0.6): each scene has one pair open, two
// slipping along different directions and one sticking.

#include <knee_contact/core/problem.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include "free_dofs.h"

#include <array>
#include <cmath>
#include <iostream>
#include <optional>
#include <sstream>
#include <string>

using namespace dealii;
using namespace knee_contact;

namespace
{
  enum State : unsigned int
  {
    open,
    stick,
    slip
  };

  const char *
  name(const unsigned int state)
  {
    static const char *names[] = {"open", "stick", "slip"};
    return names[state];
  }

  /** The solution of one state for given slip angles. */
  struct StateSolution
  {
    Vector<double>                     z;
    std::vector<double>                lambda_n;
    std::vector<std::array<double, 2>> lambda_t, s;
  };

  /**
   * The reduced problem: H z = b with the rows A z <= c (normal rows
   * 0..M-1, tangential rows M..2M-1 and 2M..3M-1).
   */
  struct Problem
  {
    Problem(const FullMatrix<double> &H,
            const Vector<double>     &b,
            const unsigned int        M,
            const double              mu)
      : H(H)
      , b(b)
      , A(3 * M, H.m())
      , c(3 * M)
      , M(M)
      , mu(mu)
    {}

    const FullMatrix<double> &H;
    const Vector<double>     &b;
    FullMatrix<double>        A;
    Vector<double>            c;
    unsigned int              M;
    double                    mu;

    std::optional<StateSolution>
    solve(const std::vector<unsigned int> &state,
          const std::vector<double>       &theta) const
    {
      const unsigned int        n_free = H.m();
      std::vector<unsigned int> normal_of(M, 0), tangential_of(M, 0);
      unsigned int              m = n_free;
      for (unsigned int p = 0; p < M; ++p)
        if (state[p] != open)
          normal_of[p] = m++;
      for (unsigned int p = 0; p < M; ++p)
        if (state[p] == stick)
          {
            tangential_of[p] = m;
            m += 2;
          }
      LAPACKFullMatrix<double> system(m, m);
      Vector<double>           rhs(m);
      for (unsigned int i = 0; i < n_free; ++i)
        {
          rhs(i) = b(i);
          for (unsigned int j = 0; j < n_free; ++j)
            system(i, j) = H(i, j);
        }
      for (unsigned int p = 0; p < M; ++p)
        {
          if (state[p] == open)
            continue;
          const double d[2] = {state[p] == slip ? std::cos(theta[p]) : 0.,
                               state[p] == slip ? std::sin(theta[p]) : 0.};
          const unsigned int k = normal_of[p];
          rhs(k)               = c(p);
          for (unsigned int j = 0; j < n_free; ++j)
            {
              system(k, j) = A(p, j);
              // The force of lambda_n: along a_N, and for a slipping pair
              // also mu lambda_n d along the tangential rows.
              system(j, k) =
                A(p, j) + mu * (d[0] * A(M + p, j) + d[1] * A(2 * M + p, j));
            }
          if (state[p] == stick)
            for (unsigned int t = 0; t < 2; ++t)
              {
                const unsigned int l = tangential_of[p] + t;
                rhs(l)               = c((1 + t) * M + p);
                for (unsigned int j = 0; j < n_free; ++j)
                  system(l, j) = system(j, l) = A((1 + t) * M + p, j);
              }
        }
      try
        {
          system.compute_lu_factorization();
          system.solve(rhs);
        }
      catch (...)
        {
          return std::nullopt; // a singular state
        }
      StateSolution result;
      result.z.reinit(n_free);
      for (unsigned int i = 0; i < n_free; ++i)
        result.z(i) = rhs(i);
      Vector<double> Az(3 * M);
      A.vmult(Az, result.z);
      result.lambda_n.assign(M, 0.);
      result.lambda_t.assign(M, {{0., 0.}});
      result.s.assign(M, {{0., 0.}});
      for (unsigned int p = 0; p < M; ++p)
        {
          for (unsigned int t = 0; t < 2; ++t)
            result.s[p][t] = Az((1 + t) * M + p) - c((1 + t) * M + p);
          if (state[p] == open)
            continue;
          result.lambda_n[p] = rhs(normal_of[p]);
          if (state[p] == stick)
            result.lambda_t[p] = {
              {rhs(tangential_of[p]), rhs(tangential_of[p] + 1)}};
          else
            result.lambda_t[p] = {
              {mu * result.lambda_n[p] * std::cos(theta[p]),
               mu * result.lambda_n[p] * std::sin(theta[p])}};
        }
      return result;
    }

    /** d x s of each slipping pair. */
    std::vector<double>
    misalignment(const std::vector<unsigned int> &slipping,
                 const std::vector<double>       &theta,
                 const StateSolution             &x) const
    {
      std::vector<double> g;
      for (const unsigned int p : slipping)
        g.push_back(std::cos(theta[p]) * x.s[p][1] -
                    std::sin(theta[p]) * x.s[p][0]);
      return g;
    }

    /**
     * The state's solution with every slipping pair's direction along its
     * slip (Newton's method on the angles from @p theta), if it is found.
     */
    std::optional<StateSolution>
    solve_aligned(const std::vector<unsigned int> &state,
                  std::vector<double>              theta,
                  const double                     u_scale) const
    {
      std::vector<unsigned int> slipping;
      for (unsigned int p = 0; p < M; ++p)
        if (state[p] == slip)
          slipping.push_back(p);
      const unsigned int k = slipping.size();
      for (unsigned int iteration = 0; iteration < 60; ++iteration)
        {
          const auto x = solve(state, theta);
          if (!x)
            return std::nullopt;
          const auto g    = misalignment(slipping, theta, *x);
          double     size = 0;
          for (const double v : g)
            size = std::max(size, std::abs(v));
          if (size <= 1e-14 * u_scale)
            return x;
          // The Jacobian of g in the angles by central differences.
          FullMatrix<double> J(k, k);
          const double       h = 1e-6;
          for (unsigned int j = 0; j < k; ++j)
            {
              auto plus = theta, minus = theta;
              plus[slipping[j]] += h;
              minus[slipping[j]] -= h;
              const auto xp = solve(state, plus), xm = solve(state, minus);
              if (!xp || !xm)
                return std::nullopt;
              const auto gp = misalignment(slipping, plus, *xp);
              const auto gm = misalignment(slipping, minus, *xm);
              for (unsigned int i = 0; i < k; ++i)
                J(i, j) = (gp[i] - gm[i]) / (2 * h);
            }
          LAPACKFullMatrix<double> L(k, k);
          L = J;
          Vector<double> step(k);
          for (unsigned int i = 0; i < k; ++i)
            step(i) = g[i];
          try
            {
              L.compute_lu_factorization();
              L.solve(step);
            }
          catch (...)
            {
              return std::nullopt;
            }
          for (unsigned int j = 0; j < k; ++j)
            theta[slipping[j]] -= std::max(-0.5, std::min(0.5, step(j)));
        }
      return std::nullopt;
    }
  };

  bool
  check(const std::string &scene, const double mu)
  {
    std::cout << "scene " << scene << std::endl;
    ContactProblem<3> problem(SOURCE_DIR "/" + scene);
    // The program's own report (its iterations' residuals, which change
    // with any change of the loop) is not what this test compares: only
    // the lines below are.
    std::ostringstream report;
    std::streambuf    *terminal = std::cout.rdbuf(report.rdbuf());
    const int          status   = problem.run();
    std::cout.rdbuf(terminal);

    const auto        &K     = problem.matrix();
    const auto        &f     = problem.rhs();
    const auto        &base  = problem.base_constraints();
    const auto        &pairs = problem.pairs();
    const unsigned int n     = K.m();
    const unsigned int M     = pairs.size();
    AssertThrow(pairs.tangential[0].size() == M &&
                  pairs.tangential[1].size() == M,
                ExcInternalError());

    // x = C0 z + g0 over the dofs free of Gamma_u.
    const FreeDofs     reduced(K, f, base);
    const unsigned int n_free = reduced.n_free;
    Problem            qp(reduced.H, reduced.b, M, mu);
    // The normal rows 0..M-1, the tangential M..2M-1 and 2M..3M-1, in z.
    std::vector<const ContactRow *> rows;
    for (unsigned int r = 0; r < M; ++r)
      rows.push_back(&pairs.rows[r]);
    for (unsigned int t = 0; t < 2; ++t)
      for (unsigned int r = 0; r < M; ++r)
        rows.push_back(&pairs.tangential[t][r]);
    rows_in_free_dofs(rows, reduced, qp.A, qp.c);

    double scale = 1e-300;
    for (unsigned int i = 0; i < n_free; ++i)
      scale = std::max(scale, std::abs(reduced.b(i)));
    // The displacement scale: the state with every pair sticking.
    const auto all_stick =
      qp.solve(std::vector<unsigned int>(M, stick), std::vector<double>(M));
    AssertThrow(all_stick.has_value(), ExcInternalError());
    const double u_scale = all_stick->z.linfty_norm();

    unsigned int              n_solutions = 0;
    std::vector<unsigned int> reference_state;
    StateSolution             reference;
    unsigned int              n_states = 1;
    for (unsigned int p = 0; p < M; ++p)
      n_states *= 3;
    for (unsigned int code = 0; code < n_states; ++code)
      {
        std::vector<unsigned int> state(M);
        for (unsigned int p = 0, rest = code; p < M; ++p, rest /= 3)
          state[p] = rest % 3;
        // Start each slipping pair along the tangential force it would
        // need to stick (the stick variant of the state), then from eight
        // directions more.
        std::vector<double> start(M, 0.);
        {
          auto stuck = state;
          for (auto &s : stuck)
            if (s == slip)
              s = stick;
          if (const auto x = qp.solve(stuck, start))
            for (unsigned int p = 0; p < M; ++p)
              if (state[p] == slip)
                start[p] = std::atan2(x->lambda_t[p][1], x->lambda_t[p][0]);
        }
        std::optional<StateSolution> x;
        for (unsigned int attempt = 0; attempt < 9 && !x; ++attempt)
          {
            auto theta = start;
            for (auto &angle : theta)
              angle += attempt * 2 * M_PI / 9;
            x = qp.solve_aligned(state, theta, u_scale);
          }
        if (!x)
          continue;
        const double   u_tolerance = 1e-11 * u_scale;
        const double   f_tolerance = 1e-11 * scale;
        bool           holds       = true;
        Vector<double> Az(3 * M);
        qp.A.vmult(Az, x->z);
        for (unsigned int p = 0; p < M; ++p)
          {
            const double slip_size = std::hypot(x->s[p][0], x->s[p][1]);
            if (state[p] == open)
              holds = holds && Az(p) - qp.c(p) <= u_tolerance;
            else
              holds = holds && x->lambda_n[p] >= -f_tolerance;
            if (state[p] == stick)
              holds =
                holds && std::hypot(x->lambda_t[p][0], x->lambda_t[p][1]) <=
                           mu * x->lambda_n[p] + f_tolerance;
            if (state[p] == slip)
              // Slipping (not at rest) and along the friction force.
              holds = holds && slip_size > u_tolerance &&
                      x->s[p][0] * x->lambda_t[p][0] +
                          x->s[p][1] * x->lambda_t[p][1] >=
                        0;
          }
        if (holds)
          {
            ++n_solutions;
            reference_state = state;
            reference       = *x;
          }
      }

    const auto &loop = problem.contact();
    std::cout << "pairs " << M << ", free dofs " << n_free
              << ", states satisfying the conditions: " << n_solutions
              << std::endl;
    if (n_solutions != 1)
      {
        std::cout << "check one admissible state: FAIL" << std::endl;
        return false;
      }
    bool same_states = true;
    std::cout << "pair  enumeration  loop" << std::endl;
    for (unsigned int p = 0; p < M; ++p)
      {
        using Status      = ContactSolution::Status;
        unsigned int mine = open;
        if (loop.status[p] == Status::stick)
          mine = stick;
        else if (loop.status[p] == Status::slip)
          mine = slip;
        same_states = same_states && mine == reference_state[p];
        std::cout << p << "     " << name(reference_state[p]) << "        "
                  << name(mine) << std::endl;
      }
    Vector<double> x_reference(n);
    reduced.C0.vmult(x_reference, reference.z);
    x_reference += reduced.g0;
    Vector<double> difference(problem.solution());
    difference -= x_reference;
    const double x_error = difference.linfty_norm() / x_reference.linfty_norm();
    double       lambda_scale = 1e-300, lambda_error = 0;
    for (unsigned int p = 0; p < M; ++p)
      lambda_scale = std::max(lambda_scale, std::abs(reference.lambda_n[p]));
    for (unsigned int p = 0; p < M; ++p)
      lambda_error =
        std::max({lambda_error,
                  std::abs(loop.lambda[p] - reference.lambda_n[p]),
                  std::abs(loop.lambda_t[p][0] - reference.lambda_t[p][0]),
                  std::abs(loop.lambda_t[p][1] - reference.lambda_t[p][1])});
    lambda_error /= lambda_scale;
    unsigned int seen = 0;
    for (const unsigned int s : reference_state)
      seen |= 1u << s;
    return friction_verdict(same_states, x_error, lambda_error, status, seen);
  }
} // namespace



int
main()
{
  // mu: the scenes' Friction coefficient.
  const bool node_to_segment = check("qp_scene_friction_3d.prm", 1.0);
  const bool mortar          = check("qp_scene_friction_3d_mortar.prm", 0.6);
  return node_to_segment && mortar ? 0 : 1;
}
