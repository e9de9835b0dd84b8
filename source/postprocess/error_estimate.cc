#include <knee_contact/postprocess/error_estimate.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace knee_contact
{
  ErrorEstimate
  estimate_error(const std::vector<double> &values,
                 const std::vector<double> &n_dofs,
                 const unsigned int         dim,
                 const double               formal_order)
  {
    ErrorEstimate     estimate;
    const std::size_t n = values.size();
    if (n == 0 || n_dofs.size() != n)
      return estimate;
    estimate.value = values.back();
    if (n < 2)
      return estimate;
    const auto ratio = [&](const std::size_t fine) {
      return std::pow(n_dofs[fine] / n_dofs[fine - 1], 1. / dim);
    };
    const double       q2 = values[n - 1], q1 = values[n - 2], e21 = q2 - q1;
    const double       r21 = ratio(n - 1);
    std::ostringstream basis;
    basis.precision(3);
    if (!std::isfinite(e21) || !(r21 > 1.01))
      {
        // No refinement between the last two meshes (or no value): nothing
        // to compare.
        estimate.basis = "the last two meshes have the same size: no estimate";
        return estimate;
      }
    double scale = 0;
    for (const double v : values)
      scale = std::max(scale, std::abs(v));
    if (std::abs(e21) <= 1e-12 * scale)
      {
        estimate.error      = 1e-12 * scale;
        estimate.asymptotic = true;
        estimate.basis      = "converged to round-off";
        return estimate;
      }
    if (n >= 3)
      {
        const double q0 = values[n - 3], e10 = q1 - q0, r10 = ratio(n - 2);
        const double quotient = e10 / e21;
        if (std::isfinite(quotient) && quotient > 0 && r10 > 1.01)
          {
            // Celik et al.'s fixed point for the order of non-uniform ratios
            // (s = 1: monotone), without their absolute value: differences
            // that grow from mesh to mesh (a singular corner's stress) give
            // a negative order, which is no convergence.
            const double log_quotient = std::log(quotient);
            double       p            = log_quotient / std::log(r21);
            bool         ok           = std::isfinite(p) && p > 0;
            for (unsigned int k = 0; k < 50 && ok; ++k)
              {
                const double a = std::pow(r21, p) - 1, b = std::pow(r10, p) - 1;
                if (!(a > 0 && b > 0))
                  {
                    ok = false;
                    break;
                  }
                const double next =
                  (log_quotient + std::log(a / b)) / std::log(r21);
                if (!(next > 0))
                  {
                    ok = false;
                    break;
                  }
                if (std::abs(next - p) < 1e-10 * std::max(1., p))
                  {
                    p = next;
                    break;
                  }
                p = next;
              }
            if (ok && std::isfinite(p) && p >= 0.5)
              {
                // Faster than the formal order is not relied on (a
                // pre-asymptotic sequence whose order still falls).
                const double used     = std::min(p, formal_order);
                const double factor   = std::pow(r21, used) - 1;
                estimate.order        = p;
                estimate.extrapolated = q2 + e21 / factor;
                estimate.error        = 1.25 * std::abs(e21) / factor;
                estimate.asymptotic   = true;
                basis << "3 meshes, observed order " << p;
                estimate.basis = basis.str();
                return estimate;
              }
            if (ok && std::isfinite(p))
              estimate.order = p;
          }
        // Outside the asymptotic range: the conservative two-mesh bar over
        // both differences.
        estimate.error = 3 * std::max(std::abs(e21), std::abs(e10)) /
                         (std::pow(r21, formal_order) - 1);
        basis << "3 meshes, not in the asymptotic range (";
        if (quotient > 0 && std::isfinite(estimate.order))
          basis << "observed order " << estimate.order;
        else if (quotient > 0)
          basis << "no order";
        else
          basis << "oscillating";
        basis << "): conservative bar";
        estimate.basis = basis.str();
        return estimate;
      }
    estimate.error = 3 * std::abs(e21) / (std::pow(r21, formal_order) - 1);
    basis << "2 meshes, order " << formal_order << " assumed";
    estimate.basis = basis.str();
    return estimate;
  }



  ErrorEstimate
  recovered_energy_estimate(const double energy, const double eta_squared)
  {
    ErrorEstimate estimate;
    estimate.value = energy;
    estimate.error = std::max(1.25 * eta_squared, 1e-13 * std::abs(energy));
    estimate.asymptotic = true;
    estimate.basis      = "strain recovery (Zienkiewicz-Zhu) on this mesh";
    return estimate;
  }



  std::map<std::string, ErrorEstimate>
  estimate_errors(const std::vector<Quantities> &cycles,
                  const std::vector<double>     &n_dofs,
                  const unsigned int             dim)
  {
    std::map<std::string, ErrorEstimate> estimates;
    if (cycles.empty())
      return estimates;
    for (const auto &[name, last] : cycles.back())
      {
        // The meshes that have the quantity, up to the finest.
        std::vector<double> values, sizes;
        for (std::size_t c = 0; c < cycles.size(); ++c)
          {
            const auto found = cycles[c].find(name);
            if (found == cycles[c].end() || !std::isfinite(found->second))
              {
                values.clear();
                sizes.clear();
                continue;
              }
            values.push_back(found->second);
            sizes.push_back(n_dofs[c]);
          }
        // Formal orders in h: the energy a(u,u) converges as the square
        // of the energy norm (2), pointwise and zone quantities (peak
        // pressure, forces, contact length, stress extremes) at the
        // energy norm's rate (1) at best near contact edges and material
        // junctions.
        estimates[name] =
          estimate_error(values, sizes, dim, name == "energy" ? 2. : 1.);
        estimates[name].value = last;
      }
    return estimates;
  }
} // namespace knee_contact
