// Goal-oriented error bars of the contact pressures: the influence (dual)
// solution of a pair's multiplier and its weighting of the recovered strain
// errors.
#include <knee_contact/base/parallel.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/postprocess/recovery.h>

#include <deal.II/base/mpi.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <set>

namespace knee_contact
{
  template <int dim>
  Vector<double>
  ContactProblem<dim>::multiplier_influence(
    const std::vector<unsigned int> &patch,
    std::vector<double>             &mu)
  {
    for (const unsigned int p : patch)
      AssertThrow(contact_system && !contact_pairs.frictional() &&
                    p < contact_pairs.size() && contact_solution.active[p],
                  ExcMessage("multiplier_influence: active pairs of a "
                             "solved frictionless problem"));
    // The contact system solves with the gaps of the rows it holds
    // (contact_pairs.rows without friction): move pair p's, solve once with
    // the active set held, restore. Any step serves (the solution is
    // affine in the gaps); one of the size of the displacement keeps the
    // difference clear of round-off.
    const double step = std::max(displacement.linfty_norm(), 1e-300);
    const auto   move = [&](const double by) {
      for (const unsigned int p : patch)
        {
          contact_pairs.rows[p].gap += by;
          contact_pairs.rows[p].reduced_gap += by;
        }
      contact_system->gaps_changed();
    };
    move(step);
    std::vector<double> excess(contact_pairs.size());
    mu.assign(contact_pairs.size(), 0.);
    Vector<double> z(dof_handler.n_dofs());
    // An error bar needs the influence to a few digits: an iterative path
    // starts from the solution and stops when the residual of the change
    // has fallen a hundredfold, whatever the patch's size (z and mu to a
    // few per cent: unit/multiplier_influence; a direct path is exact
    // anyway). Started from the previous influence instead, each solve
    // first undid the last one's change: 131 CG iterations for the four
    // influences of the 3D knee at 2.3e5 dofs, at a fixed 1e-3 of the
    // load, against 57 now.
    contact_system->set_accuracy(1e-2, true);
    contact_system->start_from(displacement);
    try
      {
        contact_system->solve(contact_solution.active, excess, mu);
        contact_system->solution(z);
      }
    catch (...)
      {
        contact_system->set_accuracy(0);
        move(-step);
        throw;
      }
    contact_system->set_accuracy(0);
    move(-step);
    z -= displacement;
    z /= step;
    for (unsigned int q = 0; q < mu.size(); ++q)
      mu[q] = (mu[q] - contact_solution.lambda[q]) / step;
    return z;
  }



  template <int dim>
  double
  ContactProblem<dim>::estimate_mesh_errors(
    const Results<dim>                         &results,
    const bool                                  uniform,
    const std::map<std::string, ErrorEstimate> &previous)
  {
    goal_indicators.clear();
    const bool frictionless_contact =
      contact_system && !contact_pairs.empty() && !contact_pairs.frictional() &&
      contact_solution.converged &&
      contact_solution.lambda.size() == contact_pairs.size();

    // The goals J = scale times the sum of lambda_q over the pairs of
    // `patch` (frictionless contact): each interface's peak pressure and
    // force.
    struct Goal
    {
      std::string               name;
      double                    value;
      std::vector<unsigned int> patch;
      double                    scale;
      std::string               basis;
      // A floor of the bar (the peak's difference from J: see below).
      double at_least = 0;
    };
    std::vector<Goal> goals;
    std::string       overall;
    double            overall_peak = 0;
    for (unsigned int i = 0;
         frictionless_contact && i < results.interfaces.size();
         ++i)
      {
        std::vector<unsigned int> active;
        int                       peak_pair = -1;
        double                    peak      = 0;
        for (unsigned int q = 0; q < contact_pairs.size(); ++q)
          if (contact_pairs.rows[q].interface == i &&
              contact_solution.active[q])
            {
              active.push_back(q);
              if (results.pressure[q] > peak)
                {
                  peak      = results.pressure[q];
                  peak_pair = q;
                }
            }
        if (peak_pair < 0)
          continue;
        const std::string prefix =
          "interface " + results.interfaces[i].name + ": ";
        // The peak pressure's goal: the mean pressure over the peak pair
        // and its neighbours (the active pairs of the interface within 1.01
        // times the distance to the nearest one), a point value regularised
        // over about two slave spacings, whose influence the strain
        // recovery resolves (Becker and Rannacher's regularised point
        // values).
        const Point<dim> &centre  = contact_pairs.points[peak_pair].position;
        double            nearest = std::numeric_limits<double>::max();
        for (const unsigned int q : active)
          if (q != unsigned(peak_pair))
            nearest =
              std::min(nearest,
                       contact_pairs.points[q].position.distance(centre));
        std::vector<unsigned int> patch;
        double                    length = 0;
        for (const unsigned int q : active)
          if (q == unsigned(peak_pair) ||
              contact_pairs.points[q].position.distance(centre) <=
                1.01 * nearest)
            {
              patch.push_back(q);
              length += contact_pairs.rows[q].length;
            }
        // J is the patch's mean pressure; the reported peak differs from
        // it by what the mesh resolves of the peak's shape, an error the
        // estimate of J does not see: where the peak stands out of its
        // patch (a sharp peak on a coarse mesh) the bar is at least that
        // difference (measured on the knee's insert-tray, whose peak is
        // sharp on the example's mesh: 0.18 to 0.71 of the true error
        // without it).
        double patch_force = 0;
        for (const unsigned int q : patch)
          patch_force += contact_solution.lambda[q];
        goals.push_back({prefix + "peak pressure",
                         peak,
                         patch,
                         1. / length,
                         "goal-oriented: the peak pair's influence and strain "
                         "recovery",
                         peak - patch_force / length});
        // The contact force: J = the sum of the interface's multipliers,
        // whose influence is that of all its active pairs.
        goals.push_back({prefix + "force",
                         results.interfaces[i].force,
                         active,
                         1.,
                         "goal-oriented: the active pairs' influence and "
                         "strain recovery"});
        if (peak > overall_peak)
          {
            overall_peak = peak;
            overall      = prefix + "peak pressure";
          }
      }

    // The contact tractions of u, for its recovered stresses (with
    // friction u's plain recovery: the tangential tractions are not
    // imposed).
    std::vector<SurfaceTraction<dim>> tractions_u;
    if (frictionless_contact)
      for (unsigned int q = 0; q < contact_pairs.size(); ++q)
        tractions_u.push_back({contact_pairs.points[q].slave_dofs[0],
                               contact_pairs.points[q].normal,
                               results.pressure[q]});

    // A bar of this mesh replaces the sequence's (unreliable on adaptive
    // meshes); with uniform refinement the larger of the two is kept (the
    // recovery does not see the error of curved boundaries approximated by
    // straight edges, the sequence does); where the value changed since
    // the previous mesh by more than both meshes' bars allow, the bar is at
    // least that change, flagged.
    const auto keep = [&](const std::string &name, ErrorEstimate bar) {
      const auto sequence = error_estimates.find(name);
      if (uniform && sequence != error_estimates.end() &&
          std::isfinite(sequence->second.error) &&
          sequence->second.error > bar.error)
        {
          bar.error      = sequence->second.error;
          bar.asymptotic = sequence->second.asymptotic;
          bar.order      = sequence->second.order;
          bar.basis      = "the larger of this mesh's bar (" + bar.basis +
                      ") and the uniform sequence's (" +
                      sequence->second.basis + ")";
        }
      const auto before = previous.find(name);
      if (before != previous.end() && std::isfinite(before->second.error))
        {
          const double change = std::abs(bar.value - before->second.value);
          if (change > bar.error + before->second.error)
            {
              bar.error      = std::max(bar.error, change);
              bar.asymptotic = false;
              bar.basis += "; it changed by more than both meshes' bars "
                           "allow since the last mesh: not converging "
                           "there, the bar is at least that change";
            }
        }
      error_estimates[name] = bar;
    };

    // The goals in batches of at most four: each batch's influences z
    // (multiplier_influence(), scaled: one more solve with the
    // factorisation each), their recoveries in one pass over the cells (the
    // first batch's with u's) and their products with u's in one more.
    // Memory: a batch holds four vectors of n_dofs and four recoveries (a
    // strain per vertex and material) beside u's, far below the factor the
    // solve already holds; the batches bound it for scenes of many
    // interfaces.
    const unsigned int                batch = 4;
    std::vector<RecoveredStrain<dim>> recovered_u;
    double eta_squared = std::numeric_limits<double>::quiet_NaN();
    for (unsigned int first = 0; first == 0 || first < goals.size();
         first += batch)
      {
        const unsigned int last =
          std::min<unsigned int>(first + batch, goals.size());
        std::vector<Vector<double>>                    z(last - first);
        std::vector<const Vector<double> *>            solutions;
        std::vector<std::vector<SurfaceTraction<dim>>> tractions;
        if (first == 0)
          {
            solutions.push_back(&displacement);
            tractions.push_back(tractions_u);
          }
        for (unsigned int g = first; g < last; ++g)
          {
            std::vector<double> mu;
            Vector<double>     &z_g = z[g - first];
            z_g                     = multiplier_influence(goals[g].patch, mu);
            z_g *= goals[g].scale;
            solutions.push_back(&z_g);
            tractions.push_back(tractions_u);
            for (unsigned int q = 0; q < contact_pairs.size(); ++q)
              tractions.back()[q].pressure =
                mu[q] * goals[g].scale / contact_pairs.rows[q].length;
          }
        std::vector<RecoveredStrain<dim>> recovered = RecoveredStrain<dim>::of(
          dof_handler, solutions, materials, tractions);
        const unsigned int offset = (first == 0 ? 1 : 0);
        if (first == 0)
          {
            recovered_u.push_back(std::move(recovered[0]));
            estimate_stress_errors(results, recovered_u[0], keep);
            if (!contact_pairs.empty() &&
                contact_solution.active.size() == contact_pairs.size())
              estimate_length_errors(results, keep);
          }

        // The products of u's recovered strain error with each z's (with
        // no goal: u's own, the energy's eta^2).
        std::vector<Influence<dim>> influences;
        for (unsigned int g = first; g < last; ++g)
          influences.push_back({&z[g - first], &recovered[g - first + offset]});
        if (goals.empty())
          influences.push_back({&displacement, &recovered_u[0]});
        std::vector<RecoveredProduct> estimates =
          recovered_error_products(dof_handler,
                                   displacement,
                                   recovered_u[0],
                                   influences,
                                   materials,
                                   !goals.empty());
        eta_squared = estimates[0].eta_u_squared;
        for (unsigned int g = first; g < last; ++g)
          {
            RecoveredProduct &estimate = estimates[g - first];
            ErrorEstimate     bar;
            bar.value = goals[g].value;
            // J(u) - J(u_h) ~ the product: its sign says which side the
            // exact value lies on. The safety factor 1.5, measured for the
            // peak pressures: |product| was 0.70 to 1.3 of the true error
            // on the adaptive knees and Hertz after two cycles (Roache's
            // 1.25 left the knee's and the gait case's third mesh outside,
            // at 0.87 and 0.89).
            bar.extrapolated = goals[g].value + estimate.product;
            bar.error =
              std::max(1.5 * std::abs(estimate.product), goals[g].at_least);
            bar.asymptotic = true;
            bar.basis      = goals[g].basis;
            keep(goals[g].name, bar);
            goal_indicators[goals[g].name] = std::move(estimate.indicators);
          }
      }
    if (!overall.empty())
      {
        error_estimates["peak pressure"] = error_estimates.at(overall);
        goal_indicators["peak pressure"] = goal_indicators.at(overall);
      }
    return eta_squared;
  }



  template <int dim>
  void
  ContactProblem<dim>::estimate_length_errors(
    const Results<dim>                                            &results,
    const std::function<void(const std::string &, ErrorEstimate)> &keep) const
  {
    // The contact zone's edge lies between an active slave vertex and an
    // inactive neighbour (one sharing a slave face): the discrete length
    // is uncertain by about one slave spacing there, the mean of the two
    // vertices' weights (2D: a length, 3D: a band's area). The bar is the
    // sum over those neighbours; it assumes the discrete active set is
    // right to within one vertex (the consistency check of keep() flags
    // where it is not).
    std::map<types::global_dof_index, unsigned int> pair_of_dof;
    for (unsigned int q = 0; q < contact_pairs.size(); ++q)
      pair_of_dof[contact_pairs.points[q].slave_dofs[0]] = q;
    // On a distributed mesh each rank sees its own cells' faces (each
    // boundary face once); the crossings are gathered below.
    std::set<std::pair<unsigned int, unsigned int>> edges;
    std::set<unsigned int>                          outline;
    std::vector<double> bars(results.interfaces.size(), 0.);
    for (const auto &cell : dof_handler.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (cell->is_locally_owned() && face->at_boundary())
          {
            std::vector<unsigned int> face_pairs;
            for (const unsigned int v : face->vertex_indices())
              {
                const auto found =
                  pair_of_dof.find(face->vertex_dof_index(v, 0));
                if (found != pair_of_dof.end())
                  face_pairs.push_back(found->second);
              }
            for (const unsigned int a : face_pairs)
              for (const unsigned int b : face_pairs)
                if (contact_solution.active[a] && !contact_solution.active[b] &&
                    contact_pairs.rows[a].interface ==
                      contact_pairs.rows[b].interface &&
                    edges.emplace(a, b).second)
                  outline.insert({a, b});
          }
    if (distributed)
      {
        std::vector<unsigned int> mine;
        for (const auto &[a, b] : edges)
          mine.insert(mine.end(), {a, b});
        const std::vector<unsigned int> all =
          parallel::gather_on_every_rank(parallel::communicator(), mine);
        for (std::size_t i = 0; i + 1 < all.size(); i += 2)
          if (edges.emplace(all[i], all[i + 1]).second)
            outline.insert({all[i], all[i + 1]});
      }
    if constexpr (dim == 2)
      {
        for (const auto &[a, b] : edges)
          bars[contact_pairs.rows[a].interface] +=
            0.5 * (contact_pairs.rows[a].length + contact_pairs.rows[b].length);
        outline.clear();
      }
    // 3D: the zone's outline is a band, one spacing wide: half the share of
    // every vertex on either side of it, each once. (Summed per crossing
    // pair, as in 2D, a vertex with two or three neighbours across counted
    // two or three times: on the Hertz sphere's tetrahedra, 9 249 to
    // 123 438 dofs, that bar was 34 to 12 times the area's difference from
    // Hertz, this one is 18 to 6 times.)
    for (const unsigned int q : outline)
      bars[contact_pairs.rows[q].interface] +=
        0.5 * contact_pairs.rows[q].length;
    for (unsigned int i = 0; i < results.interfaces.size(); ++i)
      if (results.interfaces[i].n_active > 0)
        {
          ErrorEstimate bar;
          bar.value      = results.interfaces[i].contact_length;
          bar.error      = bars[i];
          bar.asymptotic = true;
          bar.basis      = dim == 2
                             ? "one slave spacing at each edge of the contact zone"
                             : "a band one slave spacing wide along the contact "
                               "zone's outline";
          keep("interface " + results.interfaces[i].name + ": contact length",
               bar);
        }
  }



  template <int dim>
  void
  ContactProblem<dim>::estimate_stress_errors(
    const Results<dim>                                            &results,
    const RecoveredStrain<dim>                                    &recovered,
    const std::function<void(const std::string &, ErrorEstimate)> &keep) const
  {
    // Each extreme is taken over the cells' own vertex values (as the
    // pictures show them). Its bar, from the strain recovery: the largest
    // of the recovered stress's difference from the extreme at the
    // extreme's vertex (the error of the value there), the difference from
    // the recovered field's own extreme (one the cells' values miss
    // elsewhere) and the recovered stress's range over the extreme's cell
    // (where the extreme lies is known to one cell: at a body's corner,
    // where one cell meets the vertex, the recovery is that cell's own
    // value and the other two terms are zero), times 1.5. Measured on the
    // sagittal knee's uniform meshes against the finest: 0.3 to 50 times
    // the change to it; the range term is what holds the corner extremes
    // (without it 0.00 to 0.5 there). Extremes at corners and contact edges
    // are singular and grow with refinement: no bar of one mesh holds them;
    // the consistency check of keep() flags where the growth exceeds the
    // bars.
    struct Extreme
    {
      double fe = 0, recovered_there = 0, recovered = 0;
      bool   set = false;
      typename DoFHandler<dim>::active_cell_iterator cell;
      unsigned int                                   vertex = 0;
    };
    // On a distributed mesh each rank takes the extremes of its own cells
    // (the recovery is valid at their vertices), then the ranks' are
    // compared below.
    // By material: tau_yy min (as -tau_yy max), tau_yy max, von Mises max.
    std::map<types::material_id, std::array<Extreme, 3>> extremes;
    const unsigned int                                   n_vertices =
      dof_handler.get_fe().reference_cell().n_vertices();
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          const types::material_id id       = cell->material_id();
          const Material<dim>     &material = materials[id];
          auto                    &e        = extremes[id];
          for (unsigned int v = 0; v < n_vertices; ++v)
            {
              const SymmetricTensor<2, dim> stress =
                material.stress(recovered(cell->vertex_index(v), id));
              const double syy =
                results.stress_yy_at(cell->active_cell_index(), v);
              const std::array<double, 3> fe = {
                {-syy,
                 syy,
                 results.von_mises_at(cell->active_cell_index(), v)}};
              const std::array<double, 3> star = {
                {-stress[1][1], stress[1][1], material.von_mises(stress)}};
              for (unsigned int k = 0; k < 3; ++k)
                {
                  if (!e[k].set || fe[k] > e[k].fe)
                    {
                      e[k].fe              = fe[k];
                      e[k].recovered_there = star[k];
                      e[k].cell            = cell;
                      e[k].vertex          = cell->vertex_index(v);
                    }
                  e[k].recovered =
                    e[k].set ? std::max(e[k].recovered, star[k]) : star[k];
                  e[k].set = true;
                }
            }
        }
    // How many cells of its material meet each extreme's vertex (its cells
    // are this rank's or ghosts): one means a corner of the body or of a
    // material region, where the stress is often singular (flagged).
    std::map<std::pair<unsigned int, types::material_id>, unsigned int>
      cells_at;
    for (const auto &[id, e] : extremes)
      for (const Extreme &x : e)
        cells_at[{x.vertex, id}] = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (const unsigned int v : cell->vertex_indices())
          {
            const auto found =
              cells_at.find({cell->vertex_index(v), cell->material_id()});
            if (found != cells_at.end())
              ++found->second;
          }
    // Each extreme as numbers: material, kind, the value, the recovered
    // stress there, the recovered field's own extreme, the recovered
    // stress's range over the extreme's cell and the cells at its vertex.
    constexpr unsigned int width = 7;
    std::vector<double>    found;
    for (const auto &[id, e] : extremes)
      for (unsigned int k = 0; k < 3; ++k)
        {
          double low  = std::numeric_limits<double>::max(),
                 high = -std::numeric_limits<double>::max();
          for (unsigned int v = 0; v < n_vertices; ++v)
            {
              const SymmetricTensor<2, dim> stress =
                materials[id].stress(recovered(e[k].cell->vertex_index(v), id));
              const double star =
                k == 2 ? materials[id].von_mises(stress) : stress[1][1];
              low  = std::min(low, star);
              high = std::max(high, star);
            }
          found.insert(found.end(),
                       {double(id),
                        double(k),
                        e[k].fe,
                        e[k].recovered_there,
                        e[k].recovered,
                        high - low,
                        double(cells_at.at({e[k].vertex, id}))});
        }
    if (distributed)
      {
        // The largest over the ranks (the lowest rank's where equal); the
        // recovered field's own extreme the largest of all.
        const std::vector<double> all =
          parallel::gather_on_every_rank(parallel::communicator(), found);
        std::map<std::pair<int, int>, std::vector<double>> best;
        for (std::size_t i = 0; i < all.size(); i += width)
          {
            const std::vector<double> x(all.begin() + i,
                                        all.begin() + i + width);
            auto [at, added] =
              best.emplace(std::make_pair(int(x[0]), int(x[1])), x);
            if (!added)
              {
                const double recovered_max = std::max(at->second[4], x[4]);
                if (x[2] > at->second[2])
                  at->second = x;
                at->second[4] = recovered_max;
              }
          }
        found.clear();
        for (const auto &[key, x] : best)
          found.insert(found.end(), x.begin(), x.end());
      }
    const std::array<std::string, 3> names = {
      {": tau_yy min", ": tau_yy max", ": von Mises max"}};
    for (std::size_t i = 0; i < found.size(); i += width)
      {
        const types::material_id id = types::material_id(found[i]);
        const unsigned int       k  = static_cast<unsigned int>(found[i + 1]);
        const double fe = found[i + 2], recovered_there = found[i + 3],
                     recovered_extreme = found[i + 4], range = found[i + 5];
        ErrorEstimate bar;
        bar.value      = k == 0 ? -fe : fe;
        bar.error      = 1.5 * std::max({std::abs(fe - recovered_there),
                                         std::abs(fe - recovered_extreme),
                                         range});
        bar.asymptotic = found[i + 6] > 1;
        bar.basis      = "one mesh: the recovered stress at the extreme, its "
                         "own extreme and its range over the extreme's cell";
        if (!bar.asymptotic)
          bar.basis += "; the extreme lies at a corner (one cell of the "
                       "material at its vertex), where the stress is "
                       "often singular: a rough bar";
        keep(materials[id].name + names[k], bar);
      }
  }



  template Vector<double>
  ContactProblem<2>::multiplier_influence(const std::vector<unsigned int> &,
                                          std::vector<double> &);
  template Vector<double>
  ContactProblem<3>::multiplier_influence(const std::vector<unsigned int> &,
                                          std::vector<double> &);
  template double
  ContactProblem<2>::estimate_mesh_errors(
    const Results<2> &,
    const bool,
    const std::map<std::string, ErrorEstimate> &);
  template double
  ContactProblem<3>::estimate_mesh_errors(
    const Results<3> &,
    const bool,
    const std::map<std::string, ErrorEstimate> &);
} // namespace knee_contact
