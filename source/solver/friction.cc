#include <knee_contact/base/progress.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/base/tensor.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/vector.h>

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
  namespace
  {

    /**
     * Anderson mixing (Walker and Ni, SIAM J. Numer. Anal. 2011) of the
     * fixed point x = G(x) on the slipping pairs' forces: from the
     * last few iterates x_i and residuals f_i = G(x_i) - x_i, the step
     * x + f - (dX + dF) gamma with gamma minimising |f - dF gamma|. The
     * history restarts whenever the set of slipping pairs changes. Written
     * here: no library at hand mixes a fixed point that is a whole solve
     * of this loop.
     */
    class SlipForceAcceleration
    {
    public:
      std::vector<double>
      next(const std::vector<unsigned int> &pairs,
           const std::vector<double>       &x,
           const std::vector<double>       &g)
      {
        const std::size_t   m = x.size();
        std::vector<double> f(m);
        for (std::size_t i = 0; i < m; ++i)
          f[i] = g[i] - x[i];
        if (pairs != members)
          {
            members = pairs;
            dx.clear();
            df.clear();
          }
        else if (!last_x.empty())
          {
            std::vector<double> step(m), change(m);
            for (std::size_t i = 0; i < m; ++i)
              {
                step[i]   = x[i] - last_x[i];
                change[i] = f[i] - last_f[i];
              }
            dx.push_back(step);
            df.push_back(change);
            if (dx.size() > depth)
              {
                dx.erase(dx.begin());
                df.erase(df.begin());
              }
          }
        last_x = x;
        last_f = f;
        std::vector<double> result(m);
        for (std::size_t i = 0; i < m; ++i)
          result[i] = x[i] + f[i];
        const std::size_t k = df.size();
        if (k == 0 || m == 0)
          return result;
        // gamma from the normal equations, regularised against columns
        // that repeat one another.
        FullMatrix<double> normal(k, k);
        Vector<double>     right(k), gamma(k);
        double             trace = 0;
        for (std::size_t a = 0; a < k; ++a)
          {
            for (std::size_t b = 0; b < k; ++b)
              for (std::size_t i = 0; i < m; ++i)
                normal(a, b) += df[a][i] * df[b][i];
            for (std::size_t i = 0; i < m; ++i)
              right(a) += df[a][i] * f[i];
            trace += normal(a, a);
          }
        if (trace == 0)
          return result;
        for (std::size_t a = 0; a < k; ++a)
          normal(a, a) += 1e-10 * trace;
        normal.gauss_jordan();
        normal.vmult(gamma, right);
        for (std::size_t a = 0; a < k; ++a)
          for (std::size_t i = 0; i < m; ++i)
            result[i] -= gamma(a) * (dx[a][i] + df[a][i]);
        return result;
      }

    private:
      static constexpr std::size_t     depth = 8;
      std::vector<unsigned int>        members;
      std::vector<double>              last_x, last_f;
      std::vector<std::vector<double>> dx, df;
    };
  } // namespace


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
    AssertThrow(n > 0 && rows.size() % (2 * n) == 0 &&
                  (rows.size() / (2 * n) == 2 || rows.size() / (2 * n) == 3),
                ExcInternalError());
    // The rows of each pair: its normal row N, its tangential rows T_j and
    // the rows S_k that hold it when it sticks (ContactPairs::stick). A
    // pair in contact that slips has N active, one that sticks every S_k.
    const FrictionRowLayout at{n,
                               static_cast<unsigned int>(rows.size() /
                                                         (2 * n))};
    const unsigned int      dim = at.dim;
    ContactSolution         result;
    result.tolerance     = tolerance;
    const auto can_stick = [&](const unsigned int p) {
      if (bounds[p].value <= 0)
        return false;
      // Every stick row can hold, or the conditions hold it already.
      for (unsigned int k = 0; k < dim; ++k)
        if (rows[at.stick(k, p)].eliminated == numbers::invalid_dof_index &&
            !rows[at.stick(k, p)].held_by_conditions())
          return false;
      return true;
    };
    const auto set_state = [&](std::vector<bool> &state,
                               const unsigned int p,
                               const bool         contact,
                               const bool         stick) {
      state[at.normal(p)] = contact && !stick;
      for (unsigned int k = 0; k < dim; ++k)
        state[at.stick(k, p)] =
          contact && stick &&
          rows[at.stick(k, p)].eliminated != numbers::invalid_dof_index;
    };
    // Sticking: any of its stick rows active (one the conditions hold is
    // never active).
    const auto sticking_in = [&](const std::vector<bool> &state,
                                 const unsigned int       p) {
      for (unsigned int k = 0; k < dim; ++k)
        if (state[at.stick(k, p)])
          return true;
      return false;
    };
    const auto in_contact_in = [&](const std::vector<bool> &state,
                                   const unsigned int       p) {
      return state[at.normal(p)] || sticking_in(state, p);
    };
    // Start with the touching pairs (or those of the guess: the previous
    // load case's contact zone) in contact and sticking: the state in
    // which friction holds the most.
    AssertThrow(guess.empty() || guess.size() == n, ExcInternalError());
    std::vector<bool>         active(at.size(), false);
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
    // The prescribed tangential multipliers of the slipping pairs, and
    // their directions (unit vectors in the tangent plane).
    std::vector<TangentialVector> slip_force(n, TangentialVector{});
    std::vector<TangentialVector> slip_direction(n, TangentialVector{});
    // 3D: the slip directions' fixed point, accelerated (see below).
    SlipForceAcceleration acceleration;
    unsigned int          n_let_go = 0;
    // 3D on a path that takes springs: the semismooth Newton step.
    const bool          newton = dim == 3 && system.takes_springs();
    std::vector<double> spring_k(n, 0.);
    bool                sets_held = false;
    // What the bodies need of friction, measured while everything sticks
    // (the first iteration): per interface the sum of the tangential forces
    // (Cartesian) and of lambda_n.
    std::map<unsigned int, std::pair<Tensor<1, 3>, double>> needed;

    // Whether a slipping pair's Coulomb bound is taken by the Newton step
    // (below): where the path takes it.
    const auto couples = [&](const unsigned int                   p,
                             const std::vector<bool>             &state,
                             const std::vector<TangentialVector> &direction) {
      if (!system.takes_bound_couplings() || !state[p] || !bounds[p].coulomb ||
          bounds[p].value <= 0 || magnitude(direction[p]) == 0)
        return false;
      for (unsigned int j = 0; j + 1 < dim; ++j)
        if (rows[at.tangential(j, p)].eliminated == numbers::invalid_dof_index)
          return false;
      return true;
    };
    // The states seen, to stop a cycle: the active rows and what the solve
    // takes of each slipping pair, its force, or its direction where the
    // bound is coupled.
    using State = std::pair<std::vector<bool>, std::vector<TangentialVector>>;
    const auto key = [&](const std::vector<bool>             &state,
                         const std::vector<TangentialVector> &force,
                         const std::vector<TangentialVector> &direction) {
      State result{state, force};
      for (unsigned int p = 0; p < n; ++p)
        if (couples(p, state, direction))
          result.second[p] = direction[p];
      return result;
    };
    std::set<State>     seen;
    std::vector<double> excess, lambda;
    Vector<double>      load(rhs.size());
    // Inexact solves while the sets change (the iterative path; the direct
    // ones are exact): the first to 1e-2 of the load. Whatever follows the
    // loop (the error estimate's solves) asks for its own accuracy.
    bool inexact = true, had_inexact_solve = false;
    system.set_accuracy(1e-2);
    const auto finish = [&]() {
      system.set_accuracy(0);
      return result;
    };
    const auto component = [](const double v) {
      return v == 0 ? 0. : v; // no -0 in the states compared
    };
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
        // A state in which the slipping pairs let a body go may be a
        // passing one (in 3D, where every pair slips the rotation about
        // the normal is free, while the solution has a few sticking): the
        // pairs in contact stick again, twice; the third time friction
        // cannot hold the body.
        if (!free.empty() && iteration > 1 && ++n_let_go < 3)
          {
            for (unsigned int p = 0; p < n; ++p)
              if (in_contact_in(active, p))
                set_state(active, p, true, can_stick(p));
            slip_force.assign(n, TangentialVector{});
            slip_direction.assign(n, TangentialVector{});
            spring_k.assign(n, 0.);
            seen.clear();
          }
        else if (!free.empty())
          {
            // Friction lets go of a body: name the ratio it needed.
            std::ostringstream what;
            what << std::setprecision(3);
            for (const auto &[interface, forces] : needed)
              if (forces.second > 0)
                what << " (interface " << interface << ": tangential/normal "
                     << "force " << forces.first.norm() / forces.second << ")";
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
        // The semismooth Newton step (3D, where the path takes springs):
        // each slipping pair's force bound d is linearised in its slip,
        // lambda_t = bound d + k (I - d d^T) s, a spring k across d on its
        // tangential rows (k = c_s bound / |lambda_t + c_s s| of the
        // iteration that set it slipping: bound / |s| while it slips on).
        if (newton)
          {
            std::vector<ContactSystem::Spring> springs;
            for (unsigned int p = 0; p < n; ++p)
              if (active[p] && spring_k[p] > 0 &&
                  magnitude(slip_force[p]) > 0 &&
                  rows[at.tangential(0, p)].eliminated !=
                    numbers::invalid_dof_index &&
                  rows[at.tangential(1, p)].eliminated !=
                    numbers::invalid_dof_index)
                {
                  const double          f = magnitude(slip_force[p]);
                  ContactSystem::Spring spring;
                  spring.rows = {{at.tangential(0, p), -slip_force[p][1] / f},
                                 {at.tangential(1, p), slip_force[p][0] / f}};
                  spring.stiffness = spring_k[p];
                  springs.push_back(spring);
                }
            system.set_springs(springs);
          }
        // The Newton step on the Coulomb bound, where the path takes it: a
        // slipping pair's force mu lambda_n d with the lambda_n of this
        // solve (the fixed point takes the last one's: in 2D 4 to 5 steps
        // once the sets had settled, the force changing by about 1e-2 per
        // step, measured on the sagittal knee with mu = 0.04 on both
        // interfaces).
        std::vector<bool>                         coupled(n, false);
        std::vector<ContactSystem::BoundCoupling> couplings;
        for (unsigned int p = 0; p < n; ++p)
          if (couples(p, active, slip_direction))
            {
              coupled[p] = true;
              ContactSystem::BoundCoupling coupling;
              coupling.normal_row = at.normal(p);
              for (unsigned int j = 0; j + 1 < dim; ++j)
                coupling.rows.emplace_back(at.tangential(j, p),
                                           bounds[p].value *
                                             slip_direction[p][j]);
              couplings.push_back(coupling);
            }
        load = rhs;
        for (unsigned int p = 0; p < n; ++p)
          for (unsigned int j = 0; j + 1 < dim; ++j)
            if (slip_force[p][j] != 0 && !coupled[p])
              for (const auto &[dof, a] : rows[at.tangential(j, p)].row)
                load(dof) -= slip_force[p][j] * a;
        system.set_rhs(load);
        system.set_bound_couplings(couplings);
        // What this solve depends on, for the cycle test.
        const auto state = key(active, slip_force, slip_direction);
        system.solve(active, excess, lambda);
        // The force a coupled pair had in this solve.
        for (unsigned int p = 0; p < n; ++p)
          if (coupled[p])
            for (unsigned int j = 0; j + 1 < dim; ++j)
              slip_force[p][j] =
                component(bounds[p].value * lambda[p] * slip_direction[p][j]);
        // lambda_n and lambda_t of each pair: of a sticking pair from the
        // multipliers of its stick rows (stick_coefficients()).
        std::vector<TangentialVector> lambda_t(n, TangentialVector{});
        std::vector<TangentialVector> slip(n, TangentialVector{});
        for (unsigned int p = 0; p < n; ++p)
          {
            for (unsigned int j = 0; j + 1 < dim; ++j)
              slip[p][j] = excess[at.tangential(j, p)];
            if (sticking_in(active, p))
              {
                const auto &c = bounds[p].stick;
                lambda[p]     = 0;
                for (unsigned int k = 0; k < dim; ++k)
                  {
                    const double l = lambda[at.stick(k, p)];
                    lambda[p] += l * c[k][0];
                    for (unsigned int j = 0; j + 1 < dim; ++j)
                      lambda_t[p][j] += l * c[k][1 + j];
                  }
              }
            else if (active[p])
              lambda_t[p] = slip_force[p];
          }
        lambda.resize(n);
        const auto in_contact = [&](const unsigned int p) {
          return in_contact_in(active, p);
        };
        if (iteration == 1)
          for (unsigned int p = 0; p < n; ++p)
            if (in_contact(p))
              {
                // The Cartesian tangential force: sum_j lambda_t,j t_j with
                // t_j the rows of c^-1 after the normal's.
                Tensor<2, 3> F;
                for (unsigned int i = 0; i < 3; ++i)
                  for (unsigned int k = 0; k < 3; ++k)
                    F[k][i] = i < dim && k < dim ? bounds[p].stick[k][i]
                                                 : double(i == k);
                F                 = invert(F);
                auto &[t, normal] = needed[rows[p].interface];
                for (unsigned int j = 0; j + 1 < dim; ++j)
                  t += lambda_t[p][j] * F[1 + j];
                normal += lambda[p];
              }

        double lambda_scale = 0;
        for (unsigned int p = 0; p < n; ++p)
          lambda_scale = std::max(
            {lambda_scale, std::abs(lambda[p]), magnitude(lambda_t[p])});
        if (lambda_scale == 0)
          lambda_scale = 1;
        const double u_scale = std::max(system.displacement_scale(), 1e-300);
        // The slips' own scale where they exceed the displacements: a
        // moved body's slip counts its rigid sliding (Load cases/Motion:
        // 0.3 m on a block whose displacements are 1e-4 m; measured there
        // with u_scale, a slip direction right to round-off left 1.5e-10).
        double slip_scale = u_scale;
        for (const auto &s : slip)
          slip_scale = std::max(slip_scale, magnitude(s));
        const double force_scale = rhs.linfty_norm() + lambda_scale;

        std::vector<bool>             next(at.size(), false);
        std::vector<TangentialVector> next_force(n, TangentialVector{});
        std::vector<TangentialVector> next_direction(n, TangentialVector{});
        std::vector<double>           next_spring_k(n, 0.);
        result.complementarity = 0;
        result.max_penetration = -std::numeric_limits<double>::max();
        double force_change    = 0;
        // 3D: the change of the bounds' magnitudes (the slip directions
        // converge with the slip across the force, in the residual; their
        // turns stay at the solve's round-off, 1e-9 of the forces on a
        // sliding block).
        double       bound_change = 0;
        unsigned int n_contact = 0, n_stick = 0;
        // As in solve(): the first step from bodies held at points.
        std::vector<double> entry(n, 0.);
        if (iteration == 1 && guess.empty())
          {
            std::vector<bool> contact_now(n);
            for (unsigned int p = 0; p < n; ++p)
              contact_now[p] = in_contact(p);
            entry = first_step_thresholds(rows, excess, contact_now);
          }
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
              (lambda[p] + c * (excess[p] - entry[p]) > 0 ||
               (in_contact(p) && lambda[p] >= -1e-12 * force_scale));
            if (!contact)
              continue;
            ++n_contact;
            const double bound = bounds[p].coulomb
                                   ? bounds[p].value * std::max(lambda[p], 0.)
                                   : bounds[p].value;
            // A sticking pair slips where its tangential force exceeds the
            // bound, in the force's direction; a slipping pair sticks by
            // the semismooth rule below, which also turns its direction (in
            // 2D too since 2026-11-28: the sagittal knee, tests/scenes/
            // knee_small.prm with mu = 0.04 on both interfaces, took 9
            // iterations on the direct paths instead of 15 with the rule
            // "stick where it would slip against its force", s . d < 0,
            // the rule's limit c_t -> infinity; CGS-4, the gait and tray
            // paths the same iterations); a pair that comes into contact
            // starts slipping the way it moved while open.
            const TangentialVector &t_force = lambda_t[p];
            const TangentialVector &s       = slip[p];
            const double            s_norm  = magnitude(s);
            const auto              unit    = [](const TangentialVector &v) {
              const double length = magnitude(v);
              return length > 0
                                       ? TangentialVector{{v[0] / length, v[1] / length}}
                                       : TangentialVector{};
            };
            bool stick = true;
            // (A coupled pair's force has its direction only where
            // lambda_n > 0.)
            TangentialVector direction =
              coupled[p] ? slip_direction[p] : unit(slip_force[p]);
            if (magnitude(direction) == 0)
              {
                // No force yet (a bound of zero): the way it moved, or
                // along t_1.
                direction = s_norm > 0 ? unit(s) : TangentialVector{{1, 0}};
              }
            if (sticking_in(active, p))
              {
                const double t_norm = magnitude(t_force);
                // Within half the tolerance the residual allows: a pair
                // held at its bound (a load path that stops after sliding)
                // exceeds it by the solve's round-off, 1e-11 of the forces
                // on a dragged block, and at 1e-12 half the pairs slipped
                // and stuck in turn without end.
                stick = t_norm <= bound + 0.5 * tolerance * lambda_scale;
                if (t_norm > 0)
                  direction = unit(t_force);
                result.complementarity =
                  std::max(result.complementarity,
                           std::max(0., t_norm - bound) / lambda_scale);
              }
            else if (!active[p] && s_norm != 0)
              {
                // A pair that comes into contact slips the way it moved
                // while open (the large-c limit of the complementarity
                // test). Held at once, its whole tangential displacement
                // would be undone in one step: starting so, the sagittal
                // knee took 40 iterations instead of 15 at mu = 0.04
                // (measured with the slave's own tangent).
                stick     = false;
                direction = unit(s);
              }
            else if (active[p])
              {
                const double along = direction[0] * s[0] + direction[1] * s[1];
                stick              = along < 0;
                // What the slip has across its force (zero at the
                // solution: the force opposes the slip).
                // (Not sqrt(|s|^2 - along^2): that cancels to
                // sqrt(eps) |s|.)
                const double across =
                  std::abs(direction[0] * s[1] - direction[1] * s[0]);
                // (Without a bound, any slip satisfies the law.)
                if (bound > 0)
                  result.complementarity =
                    std::max({result.complementarity,
                              std::max(0., -along) / slip_scale,
                              across / slip_scale});
                if (bound > 0)
                  {
                    // The semismooth rule of Hueber, Stadler and
                    // Wohlmuth with lambda_t = bound d: stick where
                    // |lambda_t + c_t s| <= bound, else the force bound
                    // (lambda_t + c_t s) / |...|, with c_t = 0.01 E h for a
                    // pair of spacing h. With the Newton step E is the
                    // softest material's modulus (the 3D knee, E from 3.4e8
                    // to 4e11 Pa: 13 iterations with c_t up to 1e-4 E_max h,
                    // 17 at 1e-3, 52 at 1e-2; the stacked cubes and spheres
                    // of the tests alike from 1e-3 to 3e-2 E_max h); without
                    // it c_t also damps the directions' fixed point, and E
                    // is the stiffest's (with the softest's the tilted cube
                    // of tests/drivers/friction_3d.py did not converge in
                    // 100 iterations on the sparse path).
                    const double ct = 0.01 *
                                      (newton ? e_minimum : c / c_relative) *
                                      rows[p].spacing(dim);
                    const TangentialVector v{
                      {bound * direction[0] + ct * s[0],
                       bound * direction[1] + ct * s[1]}};
                    stick = magnitude(v) <= bound;
                    // With the Newton step the direction of
                    // bound d + c_s s, c_s the springs' constant
                    // (100 E_max h): the slip's own where it is large,
                    // the force's where the pair barely slips (at the
                    // stick/slip boundary the slip's own direction is that
                    // of a slip of 1e-10 of the displacements and turned
                    // the force back and forth: a small step of the 3D
                    // tray's load path, prm/tibial_tray_3d_friction.prm,
                    // took 50 iterations without converging, now 11);
                    // without it v's (a damped fixed point).
                    if (!stick)
                      {
                        const double c_s = c * rows[p].spacing(dim);
                        direction        = newton && s_norm > 0
                                             ? unit(TangentialVector{
                                          {bound * direction[0] + c_s * s[0],
                                                  bound * direction[1] + c_s * s[1]}})
                                             : unit(v);
                      }
                  }
                else if (!stick && s_norm > 0)
                  direction = unit(s);
              }
            stick = stick && can_stick(p);
            set_state(next, p, true, stick);
            if (stick)
              ++n_stick;
            else
              {
                next_direction[p] = direction;
                for (unsigned int j = 0; j + 1 < dim; ++j)
                  next_force[p][j] = component(direction[j] * bound);
                if (newton)
                  {
                    const double c_s = c * rows[p].spacing(dim);
                    const double v   = magnitude(TangentialVector{
                      {t_force[0] + c_s * s[0], t_force[1] + c_s * s[1]}});
                    next_spring_k[p] = v > 0 ? c_s * bound / v : 0.;
                  }
              }
            const TangentialVector change{
              {next_force[p][0] - slip_force[p][0],
               next_force[p][1] - slip_force[p][1]}};
            force_change = std::max(force_change, magnitude(change));
            bound_change = std::max(bound_change,
                                    std::abs(magnitude(next_force[p]) -
                                             magnitude(slip_force[p])));
          }
        // 3D: while the sets stay, the slipping pairs' forces (2-vectors in
        // their tangent planes) are a fixed point of the rules above: the
        // Coulomb bound mu lambda_n of the last iterate, and without the
        // Newton step the direction too. It converges slowly, or not at
        // all, where the bound feeds back on itself (Cattaneo-Mindlin on
        // spheres: the changes grew by 1.16 per iteration) or where the slip
        // is small beside the elastic response to turning the force: it is
        // accelerated (Anderson mixing, the multisecant form of Newton's
        // method on the forces).
        if (dim == 3)
          {
            // A coupled pair's bound is Newton's; so is its direction,
            // unless the path held its spring as a row (an infinite
            // stiffness across the slip: its direction then converges
            // linearly, a third per iteration on the stacked cubes of
            // tests/drivers/friction_3d.py, 19 iterations instead of 10).
            // Mixed where the step is exact, the condensed path took up to
            // 10 instead of 7 there.
            const bool mix_coupled = system.springs_held_as_rows();
            std::vector<unsigned int> slipping;
            for (unsigned int p = 0; p < n; ++p)
              if (next[p] && active[p] && (!coupled[p] || mix_coupled) &&
                  magnitude(slip_force[p]) > 0 && magnitude(next_force[p]) > 0)
                slipping.push_back(p);
            if (next != active || !sets_held)
              slipping.clear();
            sets_held = next == active;
            std::vector<unsigned int> members;
            std::vector<double>       now, to;
            for (const unsigned int p : slipping)
              for (unsigned int j = 0; j < 2; ++j)
                {
                  members.push_back(2 * p + j);
                  now.push_back(slip_force[p][j]);
                  to.push_back(next_force[p][j]);
                }
            const std::vector<double> mixed =
              acceleration.next(members, now, to);
            for (unsigned int i = 0; i < slipping.size(); ++i)
              {
                const unsigned int p = slipping[i];
                for (unsigned int j = 0; j < 2; ++j)
                  next_force[p][j] = component(mixed[2 * i + j]);
                // (A coupled pair takes the mixed direction.)
                if (coupled[p] && magnitude(next_force[p]) > 0)
                  for (unsigned int j = 0; j < 2; ++j)
                    next_direction[p][j] =
                      next_force[p][j] / magnitude(next_force[p]);
              }
            force_change = bound_change = 0;
            for (unsigned int p = 0; p < n; ++p)
              {
                force_change =
                  std::max(force_change,
                           magnitude(TangentialVector{
                             {next_force[p][0] - slip_force[p][0],
                              next_force[p][1] - slip_force[p][1]}}));
                bound_change = std::max(bound_change,
                                        std::abs(magnitude(next_force[p]) -
                                                 magnitude(slip_force[p])));
              }
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
        result.slip.assign(n, TangentialVector{});
        for (unsigned int p = 0; p < n; ++p)
          if (in_contact(p))
            {
              result.active[p] = true;
              result.status[p] =
                sticking_in(active, p) ? Status::stick : Status::slip;
              // The slip of a pair in contact (an open pair's tangential
              // jump is no slip).
              if (result.status[p] == Status::slip)
                result.slip[p] = slip[p];
            }
        result.lambda       = lambda;
        result.lambda_t     = lambda_t;
        const double change = dim == 2 ? force_change : bound_change;
        // A state the loop would stop in (converged, settled, cycling, out
        // of iterations) after an inexact solve (the iterative path while
        // the sets change) is solved again to the final tolerance first,
        // as in solve().
        const bool exact         = system.last_solve_exact();
        had_inexact_solve        = had_inexact_solve || !exact;
        const auto solve_exactly = [&]() {
          system.set_accuracy(0);
          inexact = false;
          seen.clear();
        };
        if (next == active && change <= tolerance * force_scale &&
            result.complementarity <= tolerance)
          {
            if (exact)
              return finish();
            solve_exactly();
            continue;
          }
        // Settled: 2D, the slip forces within the tolerance; 3D, the slip
        // directions no longer turn either (while they turn, the slip
        // across its force still shrinks).
        if (next == active && change <= tolerance * force_scale &&
            force_change <= (dim == 2 ? 1 : 1e-3) * tolerance * force_scale)
          {
            if (!exact)
              {
                solve_exactly();
                continue;
              }
            result.converged = false;
            result.failure   = "the contact and stick sets settled but the "
                               "complementarity residual stays above "
                               "Contact/Tolerance";
            return finish();
          }
        if (next == active)
          ++result.n_bound_updates;
        else if (seen.count(key(next, next_force, next_direction)))
          {
            // (A cycle under inexact solves may be the Krylov solver's
            // error: from here on every solve is exact.)
            if (inexact && had_inexact_solve)
              {
                solve_exactly();
                continue;
              }
            result.converged = false;
            result.failure =
              "the stick and slip sets cycle (iteration " +
              std::to_string(iteration) +
              " returns to an earlier state); refine the contact zone or "
              "load in smaller steps";
            return finish();
          }
        if (iteration >= max_iterations)
          {
            if (!exact)
              {
                solve_exactly();
                continue;
              }
            result.converged = false;
            result.failure =
              "no convergence in " + std::to_string(max_iterations) +
              " friction iterations; raise 'Maximum active set iterations'";
            return finish();
          }
        // While the sets change, the next solve needs only the accuracy
        // that decides them: a hundredth of the complementarity residual,
        // at most 1e-2 of the load, no less than the tolerance (as
        // solve()). Once they hold, the slip forces converge on exact
        // solves (3D knee, 2.3e5 dofs, the fourth case of the stance: 10
        // iterations; with the forcing term throughout 20, the residual
        // falling 3x per iteration from the seventh on).
        if (inexact)
          system.set_accuracy(
            next == active
              ? 0.
              : std::clamp(1e-2 * result.complementarity, tolerance, 1e-2));
        seen.insert(state);
        active         = next;
        slip_force     = next_force;
        slip_direction = next_direction;
        spring_k       = next_spring_k;
      }
  }
} // namespace knee_contact
