// The active-set loop with Coulomb friction against an independent solution
// of the same discrete problem: every state of the three pairs of
// qp_scene_friction.prm (open, stick, slip in +t, slip in -t: 4^3 = 64
// combinations) is solved densely (LAPACK) in the dofs left free by
// Gamma_u, and the one state whose solution satisfies every condition is
// the reference:
//   open:      a_N x <= g_N                  (no force)
//   stick:     a_N x = g_N, a_T x = g_T,     lambda_n >= 0, |lambda_t| <= mu
//                                            lambda_n
//   slip in d: a_N x = g_N, lambda_t = d mu lambda_n, lambda_n >= 0,
//              d (a_T x - g_T) >= 0          (it slips the way the friction
//                                            force on the master points)
// with C x - d + sum (a_N lambda_n + a_T lambda_t) = 0 (the slipping pairs
// make this system unsymmetric). This is written from the conditions, not
// from the loop: it shares only the matrix, the load and the rows (N and
// T) with the program, not the stick rows, the bounds' fixed point or the
// solver paths. Asserted: one state satisfies the conditions, the loop's
// statuses are that state, and x, lambda_n and lambda_t equal the
// reference to 1e-10 relative. Done for node-to-segment rows and for
// mortar rows, each with one pair open, one sticking and one slipping.

#include <knee_contact/core/problem.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include "free_dofs.h"

#include <iostream>
#include <string>

using namespace dealii;
using namespace knee_contact;

namespace
{
  enum State : unsigned int
  {
    open,
    stick,
    slip_plus,
    slip_minus
  };

  const char *
  name(const unsigned int state)
  {
    static const char *names[] = {"open", "stick", "slip+", "slip-"};
    return names[state];
  }

  bool
  check(const std::string &scene, const double mu)
  {
    std::cout << "scene " << scene << std::endl;
    ContactProblem<2> problem(SOURCE_DIR "/" + scene);
    const int         status = problem.run();

    const auto        &K     = problem.matrix();
    const auto        &f     = problem.rhs();
    const auto        &base  = problem.base_constraints();
    const auto        &pairs = problem.pairs();
    const unsigned int n     = K.m();
    const unsigned int M     = pairs.size();
    AssertThrow(pairs.tangential[0].size() == M, ExcInternalError());

    // x = C0 z + g0 over the dofs free of Gamma_u.
    const FreeDofs     reduced(K, f, base);
    const unsigned int n_free = reduced.n_free;
    const auto        &C0     = reduced.C0;
    const auto        &H      = reduced.H;
    const auto        &g0     = reduced.g0;
    const auto        &b      = reduced.b;

    // The normal (rows 0..M-1) and tangential (M..2M-1) rows in z.
    std::vector<const ContactRow *> rows;
    for (unsigned int r = 0; r < 2 * M; ++r)
      rows.push_back(r < M ? &pairs.rows[r] : &pairs.tangential[0][r - M]);
    FullMatrix<double> A;
    Vector<double>     c;
    rows_in_free_dofs(rows, reduced, A, c);

    double scale = 1e-300;
    for (unsigned int i = 0; i < n_free; ++i)
      scale = std::max(scale, std::abs(b(i)));

    unsigned int              n_solutions = 0;
    std::vector<unsigned int> reference_state;
    Vector<double>            reference;
    std::vector<double>       reference_n(M), reference_t(M);
    unsigned int              n_states = 1;
    for (unsigned int p = 0; p < M; ++p)
      n_states *= 4;
    for (unsigned int code = 0; code < n_states; ++code)
      {
        std::vector<unsigned int> state(M);
        for (unsigned int p = 0, rest = code; p < M; ++p, rest /= 4)
          state[p] = rest % 4;
        // Unknowns: z, then lambda_n of each pair in contact, then lambda_t
        // of each sticking pair; equations: equilibrium, then a_N z = c_N
        // (in contact), a_T z = c_T (sticking).
        std::vector<unsigned int> normal_of(M, 0), tangential_of(M, 0);
        unsigned int              m = n_free;
        for (unsigned int p = 0; p < M; ++p)
          if (state[p] != open)
            normal_of[p] = m++;
        for (unsigned int p = 0; p < M; ++p)
          if (state[p] == stick)
            tangential_of[p] = m++;
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
            const double       d = state[p] == slip_plus    ? 1.
                                   : state[p] == slip_minus ? -1.
                                                            : 0.;
            const unsigned int k = normal_of[p];
            rhs(k)               = c(p);
            for (unsigned int j = 0; j < n_free; ++j)
              {
                system(k, j) = A(p, j);
                // The force of lambda_n: along a_N, and for a slipping pair
                // also d mu lambda_n along a_T.
                system(j, k) = A(p, j) + d * mu * A(M + p, j);
              }
            if (state[p] == stick)
              {
                const unsigned int l = tangential_of[p];
                rhs(l)               = c(M + p);
                for (unsigned int j = 0; j < n_free; ++j)
                  system(l, j) = system(j, l) = A(M + p, j);
              }
          }
        system.compute_lu_factorization();
        system.solve(rhs);
        Vector<double> z(n_free), Az(2 * M);
        for (unsigned int i = 0; i < n_free; ++i)
          z(i) = rhs(i);
        A.vmult(Az, z);
        const double        u_tolerance = 1e-12 * z.linfty_norm();
        const double        f_tolerance = 1e-12 * scale;
        bool                holds       = true;
        std::vector<double> lambda_n(M, 0.), lambda_t(M, 0.);
        for (unsigned int p = 0; p < M; ++p)
          {
            if (state[p] == open)
              {
                holds = holds && Az(p) - c(p) <= u_tolerance;
                continue;
              }
            lambda_n[p] = rhs(normal_of[p]);
            holds       = holds && lambda_n[p] >= -f_tolerance;
            if (state[p] == stick)
              {
                lambda_t[p] = rhs(tangential_of[p]);
                holds       = holds &&
                        std::abs(lambda_t[p]) <= mu * lambda_n[p] + f_tolerance;
              }
            else
              {
                const double d = state[p] == slip_plus ? 1. : -1.;
                lambda_t[p]    = d * mu * lambda_n[p];
                holds = holds && d * (Az(M + p) - c(M + p)) >= -u_tolerance;
              }
          }
        if (holds)
          {
            ++n_solutions;
            reference_state = state;
            reference.reinit(n);
            C0.vmult(reference, z);
            reference += g0;
            reference_n = lambda_n;
            reference_t = lambda_t;
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
          mine = loop.lambda_t[p][0] > 0 ? slip_plus : slip_minus;
        same_states = same_states && mine == reference_state[p];
        std::cout << p << "     " << name(reference_state[p]) << "        "
                  << name(mine) << std::endl;
      }
    Vector<double> difference(problem.solution());
    difference -= reference;
    const double x_error = difference.linfty_norm() / reference.linfty_norm();
    double       lambda_scale = 1e-300, lambda_error = 0;
    for (unsigned int p = 0; p < M; ++p)
      lambda_scale = std::max(lambda_scale, std::abs(reference_n[p]));
    for (unsigned int p = 0; p < M; ++p)
      lambda_error = std::max({lambda_error,
                               std::abs(loop.lambda[p] - reference_n[p]),
                               std::abs(loop.lambda_t[p][0] - reference_t[p])});
    lambda_error /= lambda_scale;
    // The scene is meant to hold each state once (a test of all three).
    unsigned int seen = 0;
    for (const unsigned int s : reference_state)
      seen |= 1u << (s == slip_minus ? slip_plus : s);
    return friction_verdict(same_states, x_error, lambda_error, status, seen);
  }
} // namespace



int
main()
{
  // mu: the scenes' Friction coefficient.
  const bool node_to_segment = check("qp_scene_friction.prm", 0.5);
  const bool mortar          = check("qp_scene_friction_mortar.prm", 0.5);
  return node_to_segment && mortar ? 0 : 1;
}
