// estimate_error() on sequences whose exact value and order are known:
// Q(N) = Q* + C h^p with h = N^(-1/dim), on uniform (r = 2) and on uneven
// refinement ratios (as adaptive meshes give). Asserted: the observed order
// equals p to 1e-8 (Celik's fixed point for uneven ratios); for p at most
// the formal order the extrapolated value equals Q* to 1e-10 relative and
// the bar is 1.25 times the true error of the finest value (Richardson is
// exact for this sequence); for p above the formal order the bar uses the
// formal order (larger than 1.25 x the true error); sequences that
// oscillate or diverge are flagged with the conservative bar; a sequence
// converged to round-off has a round-off bar.

#include <knee_contact/postprocess/error_estimate.h>

#include <cmath>
#include <iostream>
#include <vector>

using namespace knee_contact;

namespace
{
  bool
  check(const char *what, const bool pass)
  {
    std::cout << "check " << what << ": " << (pass ? "PASS" : "FAIL")
              << std::endl;
    return pass;
  }

  std::vector<double>
  sequence(const std::vector<double> &n_dofs,
           const double               exact,
           const double               c,
           const double               p,
           const unsigned int         dim)
  {
    std::vector<double> values;
    for (const double n : n_dofs)
      values.push_back(exact + c * std::pow(std::pow(n, -1. / dim), p));
    return values;
  }
} // namespace



int
main()
{
  bool                                   ok     = true;
  const unsigned int                     dim    = 2;
  const std::vector<std::vector<double>> meshes = {
    {1000, 4000, 16000},             // uniform, r = 2
    {1000, 1700, 3100, 5200, 9000}}; // uneven ratios, 1.30 to 1.35
  for (const auto &n_dofs : meshes)
    for (const double p : {0.8, 1.0, 2.0})
      {
        const double exact = 3.5, c = -0.7;
        const auto   values = sequence(n_dofs, exact, c, p, dim);
        // Formal order 1 (a pressure) and 2 (the energy).
        for (const double formal : {1., 2.})
          {
            const ErrorEstimate e = estimate_error(values, n_dofs, dim, formal);
            const double        true_error = std::abs(values.back() - exact);
            std::cout << "N " << n_dofs.size() << " meshes, p = " << p
                      << ", formal " << formal << ": order " << e.order
                      << ", bar / true error " << e.error / true_error
                      << std::endl;
            ok = check("observed order", std::abs(e.order - p) < 1e-8) && ok;
            ok = check("asymptotic", e.asymptotic) && ok;
            if (p <= formal)
              {
                ok = check("extrapolated value",
                           std::abs(e.extrapolated - exact) < 1e-10 * exact) &&
                     ok;
                ok = check("bar = 1.25 x true error",
                           std::abs(e.error / true_error - 1.25) < 1e-8) &&
                     ok;
              }
            else
              ok = check("bar above 1.25 x true error (formal order)",
                         e.error > 1.25 * true_error) &&
                   ok;
          }
      }

  // Oscillating and diverging sequences: flagged, the conservative bar.
  const std::vector<double> n_dofs = {1000, 4000, 16000};
  {
    const ErrorEstimate e = estimate_error({1.0, 1.1, 1.05}, n_dofs, dim, 1);
    ok = check("oscillating: flagged, bar 3 max|dQ| / (r - 1)",
               !e.asymptotic && std::abs(e.error - 3 * 0.1) < 1e-12) &&
         ok;
  }
  {
    const ErrorEstimate e = estimate_error({1.0, 1.1, 1.3}, n_dofs, dim, 1);
    ok = check("diverging: flagged", !e.asymptotic && e.error > 0.2) && ok;
  }
  {
    const ErrorEstimate e =
      estimate_error({2.0, 2.0 + 1e-14, 2.0}, n_dofs, dim, 1);
    ok = check("round-off: bar 1e-12 of the value",
               e.asymptotic && std::abs(e.error - 2e-12) < 1e-20) &&
         ok;
  }
  {
    const ErrorEstimate e = estimate_error({1.0, 1.1}, {1000, 4000}, dim, 1);
    ok                    = check("two meshes: flagged, bar 3 |dQ| / (r - 1)",
               !e.asymptotic && std::abs(e.error - 0.3) < 1e-12) &&
         ok;
  }
  {
    const ErrorEstimate e = estimate_error({1.0}, {1000}, dim, 1);
    ok = check("one mesh: no bar", std::isnan(e.error)) && ok;
  }
  return ok ? 0 : 1;
}
