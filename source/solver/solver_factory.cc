#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/sparse_cholesky.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <limits>
#include <set>
#include <sstream>
#include <string>

namespace knee_contact
{
  namespace
  {
    using memory::megabytes;

    /**
     * memory::available(), the least over the ranks: each rank decides
     * from the same figure, so all take the same path.
     */
    double
    available_on_every_rank(std::string &limit)
    {
      const double available = memory::available(limit);
      if (parallel::n_ranks() == 1)
        return available;
      const auto least =
        Utilities::MPI::min_max_avg(available, parallel::communicator());
      limit = Utilities::MPI::broadcast(parallel::communicator(),
                                        limit,
                                        least.min_index);
      return least.min;
    }

    /** Said of a direct path in a run of several ranks. */
    std::string
    on_every_rank()
    {
      const unsigned int ranks = parallel::n_ranks();
      return ranks > 1 ? ", whole on each of the " + std::to_string(ranks) +
                           " ranks (not distributed)"
                       : "";
    }

    /**
     * The iterative path alone (@p reason: why): its estimate @p bytes
     * must fit in 80 % of what every rank has, or the run is refused in
     * one line; both go to @p figures.
     */
    void
    check_iterative_fits(const double                   bytes,
                         const std::string             &reason,
                         std::map<std::string, double> &figures)
    {
      std::string  limit;
      const double available            = available_on_every_rank(limit);
      figures["estimated_iterative_MB"] = bytes / 1048576.;
      figures["available_MB"]           = available / 1048576.;
      AssertThrow(bytes <= 0.8 * available,
                  ExcMessage("out of memory: the contact solve (iterative "
                             "path: " +
                             reason + ") needs about " + megabytes(bytes) +
                             " more, but " + megabytes(available) +
                             " are available (" + limit +
                             "); use fewer refinement cycles, a coarser "
                             "mesh or a machine with more memory"));
    }

    std::string
    gigaflops(const double flops)
    {
      std::ostringstream out;
      out << std::setprecision(3) << flops / 1e9 << " Gflop";
      return out.str();
    }
  } // namespace



  std::string
  solver_path_name(const SolverPath path)
  {
    switch (path)
      {
        case SolverPath::automatic:
          return "automatic";
        case SolverPath::condensed:
          return "condensed";
        case SolverPath::sparse:
          return "sparse";
        case SolverPath::iterative:
          return "iterative";
        case SolverPath::step41:
          return "step-41";
      }
    return "";
  }



  // Whether @p pairs carry friction (measured-only tangential rows).
  static bool
  frictional(const std::vector<ContactRow> &pairs)
  {
    return std::any_of(pairs.begin(), pairs.end(), [](const ContactRow &row) {
      return row.measured_only;
    });
  }



  SolverPlan
  plan_contact_system(const SolverPath                 requested,
                      const SparsityPattern           &sparsity,
                      const SparseMatrix<double>      &matrix,
                      const AffineConstraints<double> &base,
                      const std::vector<ContactRow>   &pairs,
                      const DirectFactor               requested_factor,
                      const bool                       warm_start)
  {
    // The reason and figures are written as the choice goes (its branches
    // return from several places).
    SolverPlan plan;
    auto      &figures = plan.figures;
    figures["ranks"]   = parallel::n_ranks();
    // MUMPS's factor is divided over the ranks (its memory and its work);
    // CHOLMOD's is whole on each.
    const bool mumps =
      resolve_direct_factor(requested_factor) == DirectFactor::mumps;
    plan.mumps                = mumps;
    const double factor_ranks = mumps ? parallel::n_ranks() : 1.;
    if (requested == SolverPath::step41)
      {
        // The first version's path, kept for comparison: UMFPACK's memory
        // is not known before its factorisation, so it is not estimated.
        plan.path = SolverPath::step41;
        return plan;
      }

    const auto iterative = [&](const std::string &reason) {
      plan.path      = SolverPath::iterative;
      plan.reason    = reason;
      plan.rows_only = parallel::n_ranks() > 1;
      return std::move(plan);
    };
    // The iterative path alone (the scene asks for it, or no factor can be
    // made): its own memory estimate must fit.
    const auto only_iterative = [&](const std::string &reason) {
      check_iterative_fits(
        IterativeContactSystem::estimated_bytes(sparsity, frictional(pairs)),
        reason,
        figures);
      return iterative(reason);
    };
    if (requested == SolverPath::iterative)
      // No direct path is analysed.
      return only_iterative("as Contact/Solver says");

    // Sizes of the condensed path: k contact unknowns (every free dof of
    // a row that can be active), P rows.
    // The rows only measured (friction's tangential rows) are not in the
    // condensed path's per-iteration system.
    std::set<types::global_dof_index> contact;
    double                            n_rows = 0, n_measured = 0;
    for (const auto &pair : pairs)
      if (pair.eliminated != numbers::invalid_dof_index)
        {
          if (pair.measured_only)
            ++n_measured;
          else
            ++n_rows;
          for (const auto &entry : pair.reduced_row)
            contact.insert(entry.first);
        }
    const bool friction = n_measured > 0;
    // 3D friction (FrictionRowLayout: two tangential rows per pair, a third
    // of all rows): the loop takes the semismooth Newton step, whose
    // springs (ContactSystem::set_springs()) the condensed path's
    // per-iteration system takes with the tangential rows, the sparse path
    // into a new factorisation at each iteration, and the iterative path
    // into CG's operator (the stiff ones as rows), with about one AMG
    // set-up per Newton iteration.
    const bool   newton = friction && 3 * n_measured == pairs.size();
    const double k = contact.size(), P = n_rows + (newton ? n_measured : 0);

    // The sparse path's ordering and symbolic analysis are needed for its
    // estimate and are its own first step; the condensed path reuses the
    // ordering with the contact unknowns moved last.
    // A factor past CHOLMOD's 32-bit indices would not fit in memory
    // either (2^31 entries take 20 GB): the iterative path, if it fits.
    std::unique_ptr<SparseContactSystem> &sparse = plan.sparse;
    Timer                                 choice_clock;
    try
      {
        sparse =
          std::make_unique<SparseContactSystem>(matrix, sparsity, base, pairs);
      }
    catch (const sparse_cholesky::FactorTooLarge &too_large)
      {
        figures["choice_analysis"] = choice_clock.wall_time();
        return only_iterative(too_large.what());
      }
    // The ordering and analysis made for the choice are part of the
    // solve's cost whichever path is taken (the sparse path reports them
    // itself).
    const auto keep_choice_figures = [&]() {
      auto sparse_figures        = sparse->statistics();
      figures["choice_ordering"] = sparse_figures["ordering"];
      figures["choice_analysis"] = sparse_figures["analysis"];
    };
    const double lnz = sparse->nnz_factor();
    const double fl  = sparse->flops();
    const double nnz_lower =
      (sparsity.n_nonzero_elements() + sparsity.n_rows()) / 2.;

    // Iterations the loop is expected to take: measured 1-5 from a guess
    // (a refined mesh's or load case's contact zone), up to 17 cold
    // (scripts/benchmark.py); each costs the condensed path one P x P LU.
    // With friction the stick and slip sets and the Coulomb bounds settle
    // too; every path takes the Newton step on the bound
    // (ContactSystem::set_bound_couplings()): measured 8-15 cold on the
    // sagittal knee (mu = 0.3 and 0.04, condensed and sparse alike), at
    // most 5 per case along the gait path, 10-12 per case on the 3D knee's
    // stance (34 059 dofs). The iterative path's inexact solves took 17
    // cold and 9-12 along that stance at 1.25e5 dofs.
    const double iterations =
      friction ? (warm_start ? 4 : 10) : (warm_start ? 3 : 10);
    const double iterative_iterations =
      friction ? (warm_start ? 12 : 17) : iterations;

    // Peak memory beyond what is allocated now [bytes]: the factor's values
    // and indices (about 1.2 x 8 bytes per entry measured), CHOLMOD's copy of
    // the matrix (lower triangle, 12 bytes per entry), the condensed copy
    // (all entries of the pattern, 12 bytes each); the sparse path's
    // bordered-update vectors may take as much as its factor; the condensed
    // path adds L_cc, S, S~ (k^2 each), W (k P), G and its LU (P^2 each) and
    // its factor holds the dense k x k trailing block.
    const double matrix_bytes =
      12. * nnz_lower + 12. * sparsity.n_nonzero_elements();
    // MUMPS: its share of the factor on each rank and of the matrix's
    // upper triangle it is given (two indices and a value, 16 bytes an
    // entry), beside the condensed copy (CHOLMOD keeps its analysis only).
    const double sparse_bytes = mumps ? 2 * 9.6 * lnz / factor_ranks +
                                          16. * nnz_lower / factor_ranks +
                                          12. * sparsity.n_nonzero_elements()
                                      : 2 * 9.6 * lnz + matrix_bytes;
    // With friction the Newton step on the bound adds, per tangential row,
    // its columns of W and G where it is not a loop row (2D: k + P) and at
    // most one coupled column of G per pair (P).
    const double condensed_bytes = 9.6 * (lnz + k * k / 2) + matrix_bytes +
                                   8. * (3 * k * k + k * P + 2 * P * P) +
                                   8. * ((newton ? 0 : k + P) + P) * n_measured;
    // Work [flops]: the condensed path factorises once (the trailing block
    // adds k^3/3), forms S (k^3), factorises S~ (k^3/3), W (2 k^2 P) and per
    // iteration the P x P LU (2/3 P^3).
    // Dense BLAS-3 runs about 4x the flop rate of a supernodal factorisation
    // of a 2D mesh on this machine kind (measured: potrf/syrk at k = 5 000
    // 15-20 Gflop/s, CHOLMOD 2-5 Gflop/s), so dense flops count a quarter.
    // The per-iteration LU (getrf) runs faster still: measured 61 Gflop/s
    // at P = 1 734 against CHOLMOD's 3.9 Gflop/s on the same knee mesh
    // (1.35e5 dofs, AMD EPYC, 2026-11-24), so its flops count an eighth.
    const double condensed_flops =
      fl + 0.25 * (k * k * k * (1. / 3 + 1 + 1. / 3) + 2 * k * k * P) +
      0.125 * iterations * 2. / 3 * P * P * P;
    // The sparse path refactorises only when an active set differs from its
    // factor's in more rows than a factorisation's worth of solves: from a
    // guess one factorisation and a few solves (measured 1.1-1.3
    // factorisations), cold about two per three iterations (knee, 1.1e5
    // dofs: 9 factorisations and 31 update solves in 14 iterations).
    // With friction one per iteration: a coupled solve (the Newton step
    // on the bound) takes a factor of its own set, no bordered update
    // (sagittal knee, mu = 0.04: 15 in 15 iterations).
    // With the 3D Newton step's springs, which change at every iteration,
    // about 0.7 per iteration: a set that stays is solved by GMRES on the
    // last factor (3D knee's stance, 34 059 dofs, mu = 0.04: 32
    // factorisations in 44 iterations).
    const double sparse_flops = (newton       ? 0.7 * iterations
                                 : friction   ? 1.0 * iterations
                                 : warm_start ? 1.3
                                              : 0.65 * iterations) *
                                fl / factor_ranks;

    std::string  limit;
    const double available = available_on_every_rank(limit);
    // Head room for the solution vectors and the results that follow.
    const auto fits = [&](const double bytes) {
      return bytes <= 0.8 * available;
    };
    figures["estimated_sparse_MB"]       = sparse_bytes / 1048576.;
    figures["estimated_condensed_MB"]    = condensed_bytes / 1048576.;
    figures["estimated_sparse_Gflop"]    = sparse_flops / 1e9;
    figures["estimated_condensed_Gflop"] = condensed_flops / 1e9;
    figures["available_MB"]              = available / 1048576.;
    figures["process_virtual_MB"]        = memory::process_virtual() / 1048576.;
    figures["contact_unknowns"]          = k;

    // The iterative path: its memory from the pattern; its time from
    // measured rates on this machine kind (AMD EPYC, 2 cores; the 3D
    // knee's tetrahedra at 3.4e4 and 2.3e5 dofs, 2026-11-26): a hierarchy
    // about 75 ns and a CG iteration (product and V-cycle) 3.2 to 4.7 ns
    // per matrix entry; 25 to 40 iterations per active-set iteration (to
    // 1e-2, warm started) and 100 to 160 for the final solve to 1e-12.
    // CHOLMOD's numeric factorisation ran at 2-5 Gflop/s on 2D meshes and
    // 20-25 Gflop/s on the 3D knee (larger supernodes): 10 Gflop/s here.
    const double nnz = sparsity.n_nonzero_elements();
    const double iterative_bytes =
      IterativeContactSystem::estimated_bytes(sparsity, friction);
    // With the Newton step's springs (3D knee, 1.25e5 dofs, mu = 0.04, the
    // first case of its stance, 2026-11-28): 0.9 set-ups per Newton
    // iteration, recomputed on the first hierarchy's aggregates at about
    // 50 ns per entry, 21 Krylov iterations per Newton iteration.
    const double krylov_iterations =
      (newton ? 21 : 30) * iterative_iterations + 150;
    const double setup_ns = newton ? 50 * 0.9 * iterative_iterations : 75;
    // Several ranks share the iterative path's work (the direct paths run
    // whole on each).
    const double iterative_seconds =
      1e-9 * nnz * (setup_ns + 4.7 * krylov_iterations) / parallel::n_ranks();
    const double cholmod_rate         = 10e9;
    figures["estimated_iterative_MB"] = iterative_bytes / 1048576.;
    figures["estimated_iterative_s"]  = iterative_seconds;

    SolverPath  path = requested;
    std::string reason;
    if (requested == SolverPath::automatic)
      {
        // A factor MUMPS is asked for by name: the sparse path (the
        // condensed one needs CHOLMOD's partial solves).
        path   = (requested_factor != DirectFactor::mumps &&
                condensed_flops <= sparse_flops)
                   ? SolverPath::condensed
                   : SolverPath::sparse;
        reason = "estimated " + gigaflops(condensed_flops) +
                 " condensed (k = " + std::to_string(int(k)) +
                 " contact unknowns, P = " + std::to_string(int(P)) +
                 " rows) against " + gigaflops(sparse_flops) +
                 " sparse (factorisations of " + gigaflops(fl) + ")";
        if (path == SolverPath::condensed && !fits(condensed_bytes) &&
            fits(sparse_bytes))
          {
            path = SolverPath::sparse;
            reason += "; the condensed path's " + megabytes(condensed_bytes) +
                      " exceed the " + megabytes(available) + " available";
          }
        const double direct_bytes =
          path == SolverPath::condensed ? condensed_bytes : sparse_bytes;
        const double direct_seconds =
          std::min(condensed_flops, sparse_flops) / cholmod_rate;
        std::ostringstream seconds;
        seconds << std::setprecision(2) << "; about " << direct_seconds
                << " s against " << iterative_seconds << " s iterative (AMG, "
                << int(krylov_iterations) << " CG iterations expected)";
        reason += seconds.str();
        if (fits(iterative_bytes) &&
            (!fits(direct_bytes) || iterative_seconds < direct_seconds))
          {
            if (!fits(direct_bytes))
              reason += "; the direct paths' " + megabytes(direct_bytes) +
                        " exceed the " + megabytes(available) + " available";
            keep_choice_figures();
            sparse.reset();
            return iterative(reason);
          }
      }
    else if (requested == SolverPath::condensed && !fits(condensed_bytes) &&
             fits(sparse_bytes))
      {
        path   = SolverPath::sparse;
        reason = "Contact/Solver = condensed needs about " +
                 megabytes(condensed_bytes) + " but " + megabytes(available) +
                 " are available (" + limit + ")";
      }
    else
      reason = "as Contact/Solver says";
    // A direct path that does not fit: the iterative one if it does.
    const double direct_needed =
      path == SolverPath::condensed ? condensed_bytes : sparse_bytes;
    if (!fits(direct_needed) && fits(iterative_bytes) &&
        (requested != SolverPath::condensed || !fits(sparse_bytes)))
      {
        keep_choice_figures();
        sparse.reset();
        return iterative("the " + solver_path_name(path) +
                         " path needs about " + megabytes(direct_needed) +
                         ", more than 80 % of the " + megabytes(available) +
                         " available (" + limit + ")");
      }
    // Nothing fits: name the smallest of the needs.
    if (!fits(condensed_bytes) && !fits(sparse_bytes))
      path = condensed_bytes < sparse_bytes ? SolverPath::condensed
                                            : SolverPath::sparse;
    const double needed =
      path == SolverPath::condensed ? condensed_bytes : sparse_bytes;
    AssertThrow(fits(needed),
                ExcMessage("out of memory: the contact solve needs about " +
                           megabytes(std::min(needed, iterative_bytes)) +
                           " more (" + solver_path_name(path) + " path " +
                           megabytes(needed) + ", iterative " +
                           megabytes(iterative_bytes) + "), but " +
                           megabytes(available) + " are available (" + limit +
                           "); use fewer refinement cycles, a coarser mesh "
                           "or a machine with more memory"));

    if (path == SolverPath::condensed)
      keep_choice_figures();
    plan.path         = path;
    plan.reason       = reason;
    plan.sparse_bytes = sparse_bytes;
    plan.available    = available;
    plan.limit        = limit;
    return plan;
  }



  SolverChoice
  make_contact_system(SolverPlan                               &&plan,
                      const SparsityPattern                     &sparsity,
                      const SparseMatrix<double>                &matrix,
                      const IterativeContactSystem::RowAssembly *rows,
                      const AffineConstraints<double>           &base,
                      const std::vector<ContactRow>             &pairs,
                      const RigidModeCheck                      &rigid_modes,
                      const KrylovSettings                      &krylov,
                      std::ostream                              &log)
  {
    AssertThrow(plan.rows_only == (rows != nullptr), ExcInternalError());
    SolverChoice choice;
    choice.figures     = std::move(plan.figures);
    choice.name        = solver_path_name(plan.path);
    std::string reason = std::move(plan.reason);
    auto        sparse = std::move(plan.sparse);
    if (plan.path == SolverPath::step41)
      {
        choice.system =
          std::make_unique<FullContactSystem>(matrix, base, pairs);
        return choice;
      }
    if (plan.path == SolverPath::iterative)
      {
        log << "   solver: iterative (" << reason << ")";
        if (parallel::n_ranks() > 1)
          log << ", distributed over " << parallel::n_ranks() << " ranks";
        log << std::endl;
        if (rows != nullptr)
          choice.system = std::make_unique<IterativeContactSystem>(
            sparsity, *rows, base, pairs, rigid_modes, krylov);
        else
          choice.system = std::make_unique<IterativeContactSystem>(
            matrix, base, pairs, rigid_modes, krylov);
        return choice;
      }
    if (plan.path == SolverPath::condensed)
      try
        {
          const std::vector<int> order = sparse->ordering();
          sparse.reset();
          choice.system = std::make_unique<CondensedContactSystem>(matrix,
                                                                   base,
                                                                   pairs,
                                                                   order);
          log << "   solver: condensed (" << reason << ")" << on_every_rank()
              << std::endl;
          return choice;
        }
      catch (const ContactSystem::ExcNotPositiveDefinite &)
        {
          // A body held by fewer contact unknowns than its rigid motions
          // (e.g. a single contact vertex) leaves C_ii singular; the sparse
          // path constrains before factorising.
          reason = "the interior of a body is not held without its contact "
                   "rows, which the condensed path needs";
          AssertThrow(plan.sparse_bytes <= 0.8 * plan.available,
                      ExcMessage("out of memory: the contact solve (sparse "
                                 "path) needs about " +
                                 megabytes(plan.sparse_bytes) + " more, but " +
                                 megabytes(plan.available) +
                                 " are available (" + plan.limit + ")"));
          sparse = std::make_unique<SparseContactSystem>(matrix, base, pairs);
        }
    choice.name = "sparse";
    log << "   solver: sparse (" << reason << ")";
    if (plan.mumps)
      {
        sparse->use_mumps();
        log << ", MUMPS's factor distributed over " << parallel::n_ranks()
            << (parallel::n_ranks() > 1 ? " ranks" : " rank") << std::endl;
      }
    else
      log << on_every_rank() << std::endl;
    choice.system = std::move(sparse);
    return choice;
  }



  SolverPlan
  plan_contact_system(const TrilinosWrappers::SparsityPattern &pattern,
                      const std::vector<ContactRow>           &pairs,
                      const std::string                       &reason)
  {
    // No direct path is analysed: their factors and C whole would be made
    // on a whole mesh, which a distributed run no longer has.
    SolverPlan plan;
    plan.figures["ranks"]            = parallel::n_ranks();
    plan.figures["distributed_mesh"] = 1;
    check_iterative_fits(
      IterativeContactSystem::estimated_bytes(pattern, frictional(pairs)),
      reason,
      plan.figures);
    plan.path      = SolverPath::iterative;
    plan.reason    = reason;
    plan.rows_only = true;
    return plan;
  }



  SolverChoice
  make_contact_system(SolverPlan                               &&plan,
                      const TrilinosWrappers::SparsityPattern   &pattern,
                      const IterativeContactSystem::RowAssembly &rows,
                      const AffineConstraints<double>           &base,
                      const std::vector<ContactRow>             &pairs,
                      const RigidModeCheck                      &rigid_modes,
                      const KrylovSettings                      &krylov,
                      std::ostream                              &log)
  {
    AssertThrow(plan.path == SolverPath::iterative && plan.rows_only,
                ExcInternalError());
    SolverChoice choice;
    choice.figures = std::move(plan.figures);
    choice.name    = solver_path_name(plan.path);
    log << "   solver: iterative (" << plan.reason << "), on the mesh "
        << "distributed over " << parallel::n_ranks() << " ranks" << std::endl;
    choice.system = std::make_unique<IterativeContactSystem>(
      pattern, rows, base, pairs, rigid_modes, krylov);
    return choice;
  }
} // namespace knee_contact
