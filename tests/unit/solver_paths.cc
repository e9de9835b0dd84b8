// The condensed, sparse, automatic and iterative solver paths against the
// step-41 path (the first version's solver, an independent computation of the
// same QP: it
// factorises the whole system with UMFPACK in every iteration instead of
// CHOLMOD once with a Schur complement, or CHOLMOD once per active set on a
// fixed analysis): on every contact test scene, among them floating bodies
// held only by contact, sliding (rotated Gamma_o) boundaries, hanging nodes
// of adaptive refinement and the active-set cycle with and without its
// safeguard, all must end with the same exit code, the same active set,
// displacements equal to 1e-10 relative (max norm) and
// multipliers to 1e-10 of the largest. Where the Young's moduli differ by a
// contrast r, the condition number of C and with it the round-off of either
// direct solve grows with r: there the tolerance is 1e-12 r if that is
// larger (measured: knee_small, r = 338: 1.4e-10; knee_frontal_small,
// r = 588: 1.0e-10; contrast_1e6: 1.3e-9).
// The iterative path (CG with AMG) solves each accepted set to a residual of
// Contact/Krylov tolerance = 1e-12 of its right hand side; its error is that
// times the condition number of the condensed system, which grows with the
// contrast and the mesh: it must end with the same exit and active set, and
// displacements and multipliers to 1e-8 relative, or 1e-10 r if larger
// (measured 2026-11-26: at most 1.6e-11 on the scenes of contrast below
// 1 200, 6.1e-10 on contrast_1e6); where the loop cannot converge, the same
// exit.

#include <knee_contact/core/problem.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace knee_contact;

namespace
{
  struct Run
  {
    int             status = 0;
    std::string     error; // first line of a refusal
    Vector<double>  x;
    ContactSolution contact;
    double          contrast = 1;
  };

  template <int dim>
  Run
  run(const std::string                  &scene,
      const ActiveSetSolver::LinearSolver solver,
      const DirectFactor                  factor = DirectFactor::automatic)
  {
    ContactProblem<dim> problem(SOURCE_DIR "/" + scene);
    problem.contact_solver().set_linear_solver(solver);
    problem.contact_solver().set_direct_factor(factor);
    Run result;
    // The runs' own tables are not part of this test's output.
    std::ostringstream quiet;
    std::streambuf    *terminal = std::cout.rdbuf(quiet.rdbuf());
    try
      {
        result.status = problem.run();
      }
    catch (const ExceptionBase &exc)
      {
        // A refusal (e.g. a body pulled off its contact) must be the same
        // refusal on both paths.
        result.status          = -1;
        const std::string what = exc.what();
        result.error           = what.substr(0, what.find("Stacktrace"));
      }
    std::cout.rdbuf(terminal);
    result.x        = problem.solution();
    result.contact  = problem.contact();
    result.contrast = problem.materials_of().max_youngs_modulus() /
                      problem.materials_of().min_youngs_modulus();
    return result;
  }

  /**
   * @p other against the step-41 run @p reference: same exit and refusal,
   * same final active set, displacements and multipliers to the tolerance
   * of the header. Iteration counts are printed, not compared: a pair whose
   * multiplier is zero up to round-off (an unloaded edge pair) may leave
   * one iteration earlier or later under another factorisation's
   * round-off (seen once: knee_small, 11 iterations either way).
   */
  bool
  agrees(const Run   &reference,
         const Run   &other,
         std::string &why,
         const bool   iterative)
  {
    bool ok = reference.status == other.status &&
              reference.error == other.error &&
              reference.x.size() == other.x.size() &&
              reference.contact.active == other.contact.active;
    // A loop that cannot converge (the unsafeguarded cycle) stops on the
    // iterative path too, but where it stops depends on the path: its
    // inexact early solves meet the cycle at another set and then solve
    // exactly (measured: iteration 11 with 4 active pairs against 8 with
    // 10).
    if (iterative && reference.status == 3 && other.status == 3)
      ok = reference.error == other.error;
    double dx = 0, dl = 0, l_scale = 1e-300;
    if (ok && !(iterative && reference.status == 3))
      {
        Vector<double> difference = other.x;
        difference -= reference.x;
        dx = difference.linfty_norm() /
             std::max(reference.x.linfty_norm(), 1e-300);
        for (unsigned int p = 0; p < reference.contact.lambda.size(); ++p)
          {
            l_scale = std::max(l_scale, std::abs(reference.contact.lambda[p]));
            dl      = std::max(dl,
                          std::abs(reference.contact.lambda[p] -
                                   other.contact.lambda[p]));
          }
        dl /= l_scale;
        const double tolerance =
          iterative ? std::max(1e-8, 1e-10 * reference.contrast)
                    : std::max(1e-10, 1e-12 * reference.contrast);
        ok = dx <= tolerance && dl <= tolerance;
      }
    std::ostringstream out;
    out << "exit " << reference.status << " / " << other.status
        << ", iterations " << reference.contact.n_iterations << " / "
        << other.contact.n_iterations << ", active sets "
        << (reference.contact.active == other.contact.active ? "equal"
                                                             : "differ")
        << ", |dx|/|x| = " << dx << ", |dlambda|/|lambda| = " << dl;
    why = out.str();
    return ok;
  }

  template <int dim>
  bool
  compare(const std::string &scene)
  {
    using Path            = ActiveSetSolver::LinearSolver;
    const Run    step41   = run<dim>(scene, Path::step41);
    unsigned int n_active = 0;
    for (const bool a : step41.contact.active)
      n_active += a;
    // The line is printed whole after the runs, so that their refusals
    // (on std::cerr, unbuffered) come before it wherever the file buffer
    // of std::cout happens to be flushed.
    std::ostringstream line;
    line << scene << ": "
         << (step41.error.empty() ? "exit " + std::to_string(step41.status)
                                  : std::string("refused"))
         << ", " << n_active << " active pairs";
    bool all = true;
    // The sparse path twice: CHOLMOD's factor (automatic on one process)
    // and MUMPS's (through PETSc, on one rank here; tests/drivers/parallel.py
    // runs it over several).
    for (const auto &[path, factor] :
         {std::pair{Path::condensed, DirectFactor::automatic},
          std::pair{Path::sparse, DirectFactor::automatic},
          std::pair{Path::sparse, DirectFactor::mumps},
          std::pair{Path::automatic, DirectFactor::automatic},
          std::pair{Path::iterative, DirectFactor::automatic}})
      {
        std::string why;
        const bool  ok   = agrees(step41,
                               run<dim>(scene, path, factor),
                               why,
                               path == Path::iterative);
        const auto  name = solver_path_name(path) +
                          (factor == DirectFactor::mumps ? " (MUMPS)" : "");
        line << ", " << name << " " << (ok ? "same" : "DIFFERENT");
        if (!ok)
          std::cerr << scene << " (" << name << " against step-41): " << why
                    << std::endl;
        all = all && ok;
      }
    std::cout << line.str() << std::endl;
    return all;
  }
} // namespace

int
main()
{
  const char *scenes[] = {"../scenes/contact_patch_matching.prm",
                          "../scenes/contact_patch_nonmatching.prm",
                          "../scenes/contact_separation.prm",
                          "../scenes/sliding_rotated_square.prm",
                          "../scenes/hertz_small.prm",
                          "../scenes/hertz_study_small.prm",
                          "../scenes/knee_small.prm",
                          "../scenes/knee_frontal_small.prm",
                          "qp_scene.prm",
                          "qp_scene_mortar.prm",
                          "../../prm/hard/floating_pressed.prm",
                          "../../prm/hard/rigid_sliding.prm",
                          "../../prm/hard/active_set_cycle.prm",
                          "../../prm/hard/active_set_cycle_unsafeguarded.prm",
                          "../../prm/hard/partial_closure.prm",
                          "../../prm/hard/contrast_1e6.prm",
                          "../../prm/hard/incompressible.prm",
                          "../../prm/hard/large_gap.prm",
                          "../../prm/hard/many_pairs.prm",
                          "../../prm/hard/thin_layer.prm",
                          "../../prm/hard/zero_load.prm"};
  // 3D: the contact patch tests (mortar on hexahedra and tetrahedra,
  // rotated, and across the two kinds; node-to-segment, node-to-node) and the
  // Hertz sphere (an active set found from a point contact over several
  // iterations).
  const char *scenes_3d[] = {"../scenes/contact_patch_3d_hex.prm",
                             "../scenes/contact_patch_3d_hex_rotated.prm",
                             "../scenes/contact_patch_3d_tet.prm",
                             "../scenes/contact_patch_3d_tet_rotated.prm",
                             "../scenes/contact_patch_3d_hex_on_tet.prm",
                             "../scenes/contact_patch_3d_tet_on_hex.prm",
                             "../scenes/contact_patch_3d_matching.prm",
                             "../scenes/contact_patch_3d_nodes.prm",
                             "../scenes/hertz_sphere_3d_small.prm"};
  bool        all         = true;
  for (const std::string scene : scenes)
    all = compare<2>(scene) && all;
  for (const std::string scene : scenes_3d)
    all = compare<3>(scene) && all;
  return all ? 0 : 1;
}
