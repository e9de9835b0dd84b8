// The influence (dual) solution of a contact multiplier, which the
// goal-oriented error bars of the peak pressures weight
// (ContactProblem::multiplier_influence), against a dense solve of its
// definition: with the loop's active set held, in the dofs left free by
// Gamma_u (x = C0 y + g0, H = C0^T K C0),
//   [H  A^T] [y ]   [0  ]
//   [A  0  ] [mu] = [e_p]        (A: the active rows)
// solved with LAPACK; the program's z = C0 y and mu must equal it to 1e-10
// relative. And the property the bars rely on, from a second dense solve:
// a change dd of the load (a fixed pseudo-random vector) changes
// lambda_p by z . dd, to 1e-10. For every active pair of the node-to-
// segment and the mortar scene, on each solver path (condensed, sparse,
// step-41, iterative), which each do the extra solve their own way (the
// iterative one to about 1 %, started from the solution).

#include <knee_contact/core/problem.h>

#include <deal.II/lac/lapack_full_matrix.h>

#include "free_dofs.h"

#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace knee_contact;

namespace
{
  bool
  check(const std::string &scene, const SolverPath path)
  {
    ContactProblem<2> problem(SOURCE_DIR "/" + scene);
    problem.contact_solver().set_linear_solver(path);
    {
      std::ostringstream quiet;
      std::streambuf    *terminal = std::cout.rdbuf(quiet.rdbuf());
      problem.run();
      std::cout.rdbuf(terminal);
    }
    // The iterative path's influence solves stop when the residual of the
    // change has fallen a hundredfold (ContactProblem::
    // multiplier_influence): z and mu to a few per cent (measured here at
    // most 1.2e-2 and 2.8e-2, relative to their largest entries); the
    // direct paths are exact.
    const double       tolerance = path == SolverPath::iterative ? 5e-2 : 1e-10;
    const auto        &K         = problem.matrix();
    const auto        &f         = problem.rhs();
    const auto        &pairs     = problem.pairs();
    const auto        &active    = problem.contact().active;
    const auto        &lambda    = problem.contact().lambda;
    const FreeDofs     reduced(K, f, problem.base_constraints());
    const unsigned int n = K.m(), n_free = reduced.n_free;

    std::vector<unsigned int> held;
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (active[p])
        held.push_back(p);
    const unsigned int m = n_free + held.size();
    // The KKT matrix of the held rows (a . x = g becomes a C0 y = g - a g0).
    LAPACKFullMatrix<double> kkt(m, m);
    for (unsigned int i = 0; i < n_free; ++i)
      for (unsigned int j = 0; j < n_free; ++j)
        kkt(i, j) = reduced.H(i, j);
    for (unsigned int k = 0; k < held.size(); ++k)
      for (const auto &[dof, a] : pairs.rows[held[k]].row)
        for (unsigned int j = 0; j < n_free; ++j)
          {
            kkt(n_free + k, j) += a * reduced.C0(dof, j);
            kkt(j, n_free + k) += a * reduced.C0(dof, j);
          }
    kkt.compute_lu_factorization();

    // A load change: every free dof, reproducible.
    Vector<double> dd(n);
    for (unsigned int i = 0; i < n; ++i)
      dd(i) = 1e6 * std::sin(1.0 + 3.7 * i);
    Vector<double> dd_free(n_free);
    reduced.C0.Tvmult(dd_free, dd);
    Vector<double> change(m);
    for (unsigned int i = 0; i < n_free; ++i)
      change(i) = dd_free(i);
    kkt.solve(change);

    bool ok = true;
    std::cout << scene << ", " << solver_path_name(path) << ": " << held.size()
              << " active of " << pairs.size() << " pairs" << std::endl;
    for (unsigned int k = 0; k < held.size(); ++k)
      {
        const unsigned int   p = held[k];
        std::vector<double>  mu;
        const Vector<double> z = problem.multiplier_influence({p}, mu);
        // The loop's solution must be untouched (the gap is restored).
        AssertThrow(problem.contact().lambda[p] == lambda[p],
                    ExcInternalError());

        Vector<double> dense(m);
        dense(n_free + k) = 1;
        kkt.solve(dense);
        Vector<double> y(n_free), z_dense(n);
        for (unsigned int i = 0; i < n_free; ++i)
          y(i) = dense(i);
        reduced.C0.vmult(z_dense, y);
        Vector<double> difference(z);
        difference -= z_dense;
        const double z_error = difference.linfty_norm() / z_dense.linfty_norm();
        double       mu_error = 0, mu_scale = 1e-300;
        for (unsigned int j = 0; j < held.size(); ++j)
          {
            mu_scale = std::max(mu_scale, std::abs(dense(n_free + j)));
            mu_error =
              std::max(mu_error, std::abs(mu[held[j]] - dense(n_free + j)));
          }
        mu_error /= mu_scale;
        // lambda_p's change under dd: dense solve vs z . dd.
        const double predicted = z * dd, actual = change(n_free + k);
        const double influence_error =
          std::abs(predicted - actual) / std::abs(actual);
        const bool pass = z_error <= tolerance && mu_error <= tolerance &&
                          influence_error <= tolerance;
        std::cout << "  pair " << p << ": check z, mu and lambda_p's change "
                  << "z . dd against the dense KKT solve to " << tolerance
                  << ": " << (pass ? "PASS" : "FAIL") << std::endl;
        if (!pass || std::getenv("KC_TEST_VERBOSE"))
          std::cout << "    errors " << z_error << ' ' << mu_error << ' '
                    << influence_error << std::endl;
        ok = ok && pass;
      }
    return ok && !held.empty();
  }
} // namespace



int
main()
{
  bool ok = true;
  for (const char *scene : {"qp_scene.prm", "qp_scene_mortar.prm"})
    for (const SolverPath path : {SolverPath::condensed,
                                  SolverPath::sparse,
                                  SolverPath::step41,
                                  SolverPath::iterative})
      ok = check(scene, path) && ok;
  std::cout << (ok ? "all PASS" : "FAIL") << std::endl;
  return ok ? 0 : 1;
}
