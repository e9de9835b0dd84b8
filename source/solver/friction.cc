#include <knee_contact/core/progress.h>
#include <knee_contact/solver/active_set.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>

// The active-set loop with friction (ActiveSetSolver::solve_with_friction).
// Written by hand for the reason solve() is: no library solves contact with
// friction between bodies on rows like these.
namespace knee_contact
{
  ContactSolution
  ActiveSetSolver::solve_with_friction(ContactSystem                    &system,
                                       const Vector<double>             &rhs,
                                       const AffineConstraints<double>  &base,
                                       const std::vector<ContactRow>    &rows,
                                       const std::vector<FrictionBound> &bounds,
                                       const RigidModeCheck    &rigid_modes,
                                       const std::vector<bool> &guess,
                                       std::ostream            &log) const
  {
    using Status         = ContactSolution::Status;
    const unsigned int n = bounds.size();
    AssertThrow(rows.size() == 4 * n, ExcInternalError());
    ContactSolution result;
    // The rows of pair p: N p, T n + p, and the two that hold it when it
    // sticks, X 2n + p and Y 3n + p (ContactPairs::stick_x, stick_y). A
    // pair in contact that slips has N active, one that sticks X and Y.
    const auto can_stick = [&](const unsigned int p) {
      return bounds[p].value > 0 &&
             rows[2 * n + p].eliminated != numbers::invalid_dof_index &&
             rows[3 * n + p].eliminated != numbers::invalid_dof_index;
    };
    const auto set_state = [n](std::vector<bool> &state,
                               const unsigned int p,
                               const bool         contact,
                               const bool         stick) {
      state[p]         = contact && !stick;
      state[2 * n + p] = contact && stick;
      state[3 * n + p] = contact && stick;
    };
    // Start with the touching pairs (or those of the guess: the previous
    // load case's contact zone) in contact and sticking: the state in
    // which friction holds the most.
    AssertThrow(guess.empty() || guess.size() == n, ExcInternalError());
    std::vector<bool>         active(4 * n, false);
    std::vector<unsigned int> by_gap;
    for (unsigned int p = 0; p < n; ++p)
      if (rows[p].eliminated != numbers::invalid_dof_index)
        {
          if (guess.empty() ? rows[p].gap <= 0 : bool(guess[p]))
            set_state(active, p, true, can_stick(p));
          else
            by_gap.push_back(p);
        }
    // As solve() does: a body only contact holds may need more.
    close_until_held(base, rows, by_gap, rigid_modes, active, [&](auto p) {
      set_state(active, p, true, can_stick(p));
    });
    // The prescribed tangential multipliers of the slipping pairs.
    std::vector<double> slip_force(n, 0.);
    // What the bodies need of friction, measured while everything sticks
    // (the first iteration): per interface |sum lambda_t| and sum lambda_n.
    std::map<unsigned int, std::pair<double, double>> needed;

    std::set<std::pair<std::vector<bool>, std::vector<double>>> seen;
    std::vector<double>                                         excess, lambda;
    Vector<double> load(rhs.size());
    for (unsigned int iteration = 1;; ++iteration)
      {
        if (iteration == 1)
          rigid_modes.check(base,
                            rows,
                            active,
                            "add a displacement or sliding boundary, or "
                            "bring it into contact (zero gap)");
        // Without a slipping pair the load pulls a body off its contact,
        // as in solve(); with one, friction lets it go.
        if (std::none_of(active.begin(), active.begin() + n, [](bool a) {
              return a;
            }))
          rigid_modes.check(base,
                            rows,
                            active,
                            "at active-set iteration " +
                              std::to_string(iteration) +
                              " its load pulls it off its contact pairs");
        const std::string free = rigid_modes.free_motion(base, rows, active);
        if (!free.empty())
          {
            // Friction lets go of a body: name the ratio it needed.
            std::ostringstream what;
            what << std::setprecision(3);
            for (const auto &[interface, forces] : needed)
              if (forces.second > 0)
                what << " (interface " << interface << ": tangential/normal "
                     << "force " << std::abs(forces.first) / forces.second
                     << ")";
            AssertThrow(false,
                        ExcMessage(
                          free +
                          "; friction cannot hold it at active-set "
                          "iteration " +
                          std::to_string(iteration) +
                          ": the load needs more tangential force than the "
                          "friction law allows" +
                          what.str() +
                          "; raise the friction coefficient or hold the "
                          "body by a boundary condition"));
          }
        load = rhs;
        for (unsigned int p = 0; p < n; ++p)
          if (slip_force[p] != 0)
            for (const auto &[dof, a] : rows[n + p].row)
              load(dof) -= slip_force[p] * a;
        system.set_rhs(load);
        system.solve(active, excess, lambda);
        // lambda_n and lambda_t of each pair: of a sticking pair from the
        // multipliers of its X and Y rows (stick_coefficients()).
        for (unsigned int p = 0; p < n; ++p)
          if (active[2 * n + p])
            {
              const auto  &c  = bounds[p].stick;
              const double lx = lambda[2 * n + p], ly = lambda[3 * n + p];
              lambda[p]     = lx * c[0][0] + ly * c[1][0];
              lambda[n + p] = lx * c[0][1] + ly * c[1][1];
            }
          else
            lambda[n + p] = active[p] ? slip_force[p] : 0.;
        lambda.resize(2 * n);
        const auto in_contact = [&](const unsigned int p) {
          return active[p] || active[2 * n + p];
        };
        if (iteration == 1)
          for (unsigned int p = 0; p < n; ++p)
            if (in_contact(p))
              {
                auto &[t, normal] = needed[rows[p].interface];
                t += lambda[n + p];
                normal += lambda[p];
              }

        double lambda_scale = 0;
        for (const double l : lambda)
          lambda_scale = std::max(lambda_scale, std::abs(l));
        if (lambda_scale == 0)
          lambda_scale = 1;
        const double u_scale = std::max(system.displacement_scale(), 1e-300);
        const double force_scale = rhs.linfty_norm() + lambda_scale;

        std::vector<bool>   next(4 * n, false);
        std::vector<double> next_force(n, 0.);
        result.complementarity    = 0;
        result.max_penetration    = -std::numeric_limits<double>::max();
        double       force_change = 0;
        unsigned int n_contact = 0, n_stick = 0;
        for (unsigned int p = 0; p < n; ++p)
          {
            result.max_penetration =
              std::max(result.max_penetration, excess[p]);
            result.complementarity =
              std::max(result.complementarity,
                       std::abs(std::min(lambda[p] / lambda_scale,
                                         -excess[p] / u_scale)));
            const bool contact =
              rows[p].eliminated != numbers::invalid_dof_index &&
              (lambda[p] + c * excess[p] > 0 ||
               (in_contact(p) && lambda[p] >= -1e-12 * force_scale));
            if (!contact)
              continue;
            ++n_contact;
            const double bound = bounds[p].coulomb
                                   ? bounds[p].value * std::max(lambda[p], 0.)
                                   : bounds[p].value;
            // A sticking pair slips where its tangential force exceeds the
            // bound, in the force's direction; a slipping pair sticks where
            // it would slip against its friction force; a pair that comes
            // into contact starts sticking. (Complementarity with the
            // constant c, lambda_t + c s, oscillates between the two
            // directions of slip where c s outweighs the bound, measured on
            // the knee; these are its limits c -> 0 and c -> infinity.)
            const double t_force = lambda[n + p], s = excess[n + p];
            bool         stick = true;
            double direction = slip_force[p] != 0 ? (slip_force[p] > 0 ? 1 : -1)
                                                  : (t_force + s >= 0 ? 1 : -1);
            if (active[2 * n + p])
              {
                stick     = std::abs(t_force) <= bound + 1e-12 * force_scale;
                direction = t_force >= 0 ? 1 : -1;
                result.complementarity =
                  std::max(result.complementarity,
                           std::max(0., std::abs(t_force) - bound) /
                             lambda_scale);
              }
            else if (!active[p] && s != 0)
              {
                // A pair that comes into contact slips the way it moved
                // while open (the large-c limit of the complementarity
                // test). Held at once, its whole tangential displacement
                // would be undone in one step: starting so, the sagittal
                // knee took 40 iterations instead of 15 at mu = 0.04
                // (measured with the slave's own tangent).
                stick     = false;
                direction = s > 0 ? 1 : -1;
              }
            else if (active[p])
              {
                if (slip_force[p] == 0)
                  direction = s >= 0 ? 1 : -1;
                stick = direction * s < 0;
                result.complementarity =
                  std::max(result.complementarity,
                           std::max(0., -direction * s) / u_scale);
              }
            stick = stick && can_stick(p);
            set_state(next, p, true, stick);
            if (stick)
              ++n_stick;
            else
              next_force[p] = direction * bound;
            force_change =
              std::max(force_change, std::abs(next_force[p] - slip_force[p]));
          }
        result.n_iterations = iteration;
        log << "   friction iteration " << std::setw(2) << iteration << ": "
            << std::setw(5) << n_contact << " in contact, " << std::setw(5)
            << n_stick << " sticking, " << std::setw(5) << n_contact - n_stick
            << " slipping, residual " << std::scientific << std::setprecision(2)
            << result.complementarity << ", slip force change "
            << force_change / force_scale << std::defaultfloat
            << Progress::stamp(log) << std::endl;

        // The pairs' figures of this iteration, also when it fails (the
        // results of a failed case are still reported, and a study or a
        // load path reads them).
        result.active.assign(n, false);
        result.status.assign(n, Status::open);
        result.slip.assign(n, 0.);
        for (unsigned int p = 0; p < n; ++p)
          if (in_contact(p))
            {
              result.active[p] = true;
              result.status[p] =
                active[2 * n + p] ? Status::stick : Status::slip;
              // The slip of a pair in contact (an open pair's tangential
              // jump is no slip).
              if (result.status[p] == Status::slip)
                result.slip[p] = excess[n + p];
            }
        result.lambda.assign(lambda.begin(), lambda.begin() + n);
        result.lambda_t.assign(lambda.begin() + n, lambda.begin() + 2 * n);
        if (next == active && force_change <= tolerance * force_scale &&
            result.complementarity <= tolerance)
          return result;
        if (next == active && force_change <= tolerance * force_scale)
          {
            result.converged = false;
            result.failure   = "the contact and stick sets settled but the "
                               "complementarity residual stays above "
                               "Contact/Tolerance";
            return result;
          }
        if (next == active)
          ++result.n_bound_updates;
        else if (seen.count({next, next_force}))
          {
            result.converged = false;
            result.failure =
              "the stick and slip sets cycle (iteration " +
              std::to_string(iteration) +
              " returns to an earlier state); refine the contact zone or "
              "load in smaller steps";
            return result;
          }
        if (iteration >= max_iterations)
          {
            result.converged = false;
            result.failure =
              "no convergence in " + std::to_string(max_iterations) +
              " friction iterations; raise 'Maximum active set iterations'";
            return result;
          }
        seen.insert({active, slip_force});
        active     = next;
        slip_force = next_force;
      }
  }
} // namespace knee_contact
