// The elastic stiffness C and the contact rows made on the distributed mesh
// (issue 38) against those of the whole mesh, on 2 and 3 ranks: each scene
// is run as a whole on every rank (its direct path holds C whole), its mesh
// is distributed (distribute_mesh()), the DoFs numbered on the distributed
// mesh, and
// - ElasticityAssembler::assemble_cells() adds the cells each rank owns
//   into a Trilinos matrix whose rows the ranks own (a ghost row's entries
//   sent to its owner). The scene's solution x, carried to the new
//   numbering by body and vertex position (every element is linear: its
//   dofs sit at the vertices), gives C x on both. Asserted, to 1e-12
//   relative to the largest entry (a sum of the same cell matrices in
//   another order): every owned row of C x, and the energy x^T C x;
// - BoundaryConditions::make_constraints() makes the Gamma_u and Gamma_o
//   lines of each rank's dofs and gathers them: on every rank the same
//   constrained dofs as the whole mesh's (carried back), the same entries
//   and inhomogeneities to 1e-12 relative to the line's largest (the
//   normals of sliding faces summed in another order);
// - ContactInterfaces::make_pairs() collects the sides from the faces of
//   the cells each rank owns and gathers them (keyed by the whole mesh's
//   vertex indices), with those lines. Asserted on every rank: the same
//   rows in the same
//   order, each row's slave position, gap, weight, entries (dofs carried
//   back) and the same after the lines' substitution, to 1e-12 relative to
//   the row's largest, and the same eliminated dof.
// - the contact solve on the distributed mesh: the iterative path
//   (IterativeContactSystem on the DoF handler's ownership, C's rows from
//   the owned cells, the rows of the lines' dofs gathered; every set's
//   condensed pattern from ActiveSetSolver::make_sparsity_pattern on each
//   rank's rows; d from the owned cells summed over the ranks; RigidModes
//   from every dof's owner) under the scene's active-set loop, CG to 1e-12
//   of |b|. Asserted: the whole run's active set (its direct path) and its
//   displacements to 1e-8 of max |u| (measured 2e-13 and below; the issue's
//   goal for a parallel run). Mutation checked by hand: without the line
//   rows' gather CG does not converge (the condensed matrix lacks rows);
// - compute_results() on it (owned cells and dofs, sums and extremes over
//   the ranks): energy, max |u|, load, every reaction, each material's
//   von Mises maximum and tau_yy range, each interface's force, peak
//   pressure and contact length, to 1e-8 of their scales (without the
//   reactions' sum over the ranks: DIFFERENT);
// - the error estimate's pieces on it: RecoveredStrain::of() (each rank's
//   cells and ghosts, the contact pressures imposed) and
//   recovered_error_products(), eta_u^2 and two products to 1e-8 of
//   eta_u^2, the indicators' sum to 1e-5 (recovering from the owned cells
//   alone: DIFFERENT).
// Scenes: 3D tetrahedra (the contact patch: mortar; and rotated, its
// sliding bottom a slanted plane; the Hertz sphere at 9 249 dofs, where
// ML's hierarchy has levels below the finest: 226 mortar rows), 3D
// hexahedra (the QP scene: mortar, non-matching) and 2D quadrilaterals
// (the QP scene: node-to-segment), two bodies each. Printed by rank 0, the
// same for any number of ranks; KNEE_CONTACT_TEST_VERBOSE prints the
// displacements' difference to stderr.

#include <knee_contact/base/parallel.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/postprocess/problem_access.h>
#include <knee_contact/postprocess/recovery.h>
#include <knee_contact/postprocess/results.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/trilinos_vector.h>

#include <deal.II/dofs/dof_tools.h>

#include "run_quietly.h"

#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>

using namespace dealii;
using namespace knee_contact;

namespace
{
  // A vertex by its body and position: the bodies' surfaces in contact
  // share positions.
  template <int dim>
  std::array<double, dim + 1>
  key(const unsigned int body, const Point<dim> &p)
  {
    std::array<double, dim + 1> k;
    k[0] = body;
    for (unsigned int d = 0; d < dim; ++d)
      k[d + 1] = p[d];
    return k;
  }

  template <int dim>
  void
  check(const std::string &scene)
  {
    const MPI_Comm      comm = knee_contact::parallel::communicator();
    ContactProblem<dim> problem(SOURCE_DIR "/" + scene);
    run_quietly(problem, scene);
    const DoFHandler<dim> &whole_dofs = problem.dof_handler_of();
    const Vector<double>  &x          = problem.solution();
    Vector<double>         Cx(x.size());
    problem.matrix().vmult(Cx, x);
    double x_C_x = x * Cx;

    // The whole mesh's dofs by body and vertex position (the distributed
    // mesh's vertices are copies of these, bit for bit).
    Triangulation<dim> whole;
    whole.copy_triangulation(whole_dofs.get_triangulation());
    unsigned int                    n_bodies = 0;
    const std::vector<unsigned int> bodies = compute_body_ids(whole, n_bodies);
    std::map<std::array<double, dim + 1>,
             std::array<types::global_dof_index, dim>>
      dofs_at;
    for (const auto &cell : whole_dofs.active_cell_iterators())
      for (const unsigned int v : cell->vertex_indices())
        for (unsigned int d = 0; d < dim; ++d)
          dofs_at[key(bodies[cell->active_cell_index()], cell->vertex(v))][d] =
            cell->vertex_dof_index(v, d);
    DistributedMesh<dim> mesh;
    distribute_mesh(whole, bodies, n_bodies, {}, mesh);
    DoFHandler<dim> dofs(mesh.triangulation);
    dofs.distribute_dofs(whole_dofs.get_fe());
    const IndexSet                    owned = dofs.locally_owned_dofs();
    TrilinosWrappers::SparsityPattern pattern;
    make_distributed_pattern(dofs, pattern);
    TrilinosWrappers::SparseMatrix C;
    C.reinit(pattern);
    const ElasticityAssembler<dim> assembler(problem.materials_of(),
                                             problem.boundary_conditions_of());
    assembler.assemble_cells(
      dofs,
      [](const types::global_dof_index) { return true; },
      [&](const std::vector<types::global_dof_index> &indices,
          const FullMatrix<double>                   &cell_matrix) {
        C.add(indices, cell_matrix);
      });
    C.compress(VectorOperation::add);

    // x in the distributed numbering, then C x there.
    TrilinosWrappers::MPI::Vector x_here(owned, comm), Cx_here(owned, comm);
    std::map<types::global_dof_index, types::global_dof_index> whole_of;
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          for (unsigned int d = 0; d < dim; ++d)
            {
              const auto i = cell->vertex_dof_index(v, d);
              whole_of[i] =
                dofs_at.at(key(mesh.body_of_cell[cell->active_cell_index()],
                               cell->vertex(v)))[d];
              if (owned.is_element(i))
                x_here(i) = x(whole_of[i]);
            }
    x_here.compress(VectorOperation::insert);
    C.vmult(Cx_here, x_here);
    double largest = Cx.linfty_norm(), difference = 0;
    for (const auto i : owned)
      difference =
        std::max(difference, std::abs(Cx_here(i) - Cx(whole_of.at(i))));
    difference          = Utilities::MPI::max(difference, comm);
    const double energy = x_here * Cx_here;

    // The contact rows. The whole numbering of every dof here, on every
    // rank, and the scene's lines in this numbering.
    std::map<types::global_dof_index, types::global_dof_index> here_of;
    for (const auto &part : Utilities::MPI::all_gather(comm, whole_of))
      for (const auto &[i, w] : part)
        {
          whole_of[i] = w;
          here_of[w]  = i;
        }
    AffineConstraints<double> lines;
    problem.boundary_conditions_of().make_constraints(dofs, lines);
    const AffineConstraints<double> &whole_lines = problem.base_constraints();
    bool lines_agree = lines.n_constraints() == whole_lines.n_constraints();
    for (const auto &line : whole_lines.get_lines())
      {
        const auto i = here_of.at(line.index);
        if (!lines.is_constrained(i))
          {
            lines_agree = false;
            continue;
          }
        const auto &here_entries = *lines.get_constraint_entries(i);
        std::map<types::global_dof_index, double> here;
        for (const auto &[j, c] : here_entries)
          here[whole_of.at(j)] = c;
        double scale = std::max(1., std::abs(line.inhomogeneity));
        for (const auto &[j, c] : line.entries)
          scale = std::max(scale, std::abs(c));
        lines_agree &= here.size() == line.entries.size() &&
                       std::abs(lines.get_inhomogeneity(i) -
                                line.inhomogeneity) <= 1e-12 * scale;
        for (const auto &[j, c] : line.entries)
          lines_agree &=
            here.count(j) == 1 && std::abs(here[j] - c) <= 1e-12 * scale;
      }
    lines_agree = Utilities::MPI::min(int(lines_agree), comm) == 1;
    const ContactPairs<dim> pairs =
      problem.contact_interfaces_of().make_pairs(dofs, lines, &mesh.vertex_id);
    const ContactPairs<dim> &reference = problem.pairs();
    const auto same = [](const double a, const double b, const double scale) {
      return std::abs(a - b) <= 1e-12 * scale;
    };
    const auto same_entries =
      [&](
        const std::vector<std::pair<types::global_dof_index, double>> &here,
        const std::vector<std::pair<types::global_dof_index, double>> &whole) {
        std::map<types::global_dof_index, double> a, b;
        double                                    scale = 1e-300;
        for (const auto &[i, c] : here)
          a[whole_of.at(i)] = c;
        for (const auto &[i, c] : whole)
          {
            b[i]  = c;
            scale = std::max(scale, std::abs(c));
          }
        bool equal = a.size() == b.size();
        for (const auto &[i, c] : b)
          equal &= a.count(i) == 1 && same(a[i], c, scale);
        return equal;
      };
    bool rows_agree = pairs.size() == reference.size();
    for (unsigned int p = 0; rows_agree && p < pairs.size(); ++p)
      {
        const ContactRow &here = pairs.rows[p], &whole = reference.rows[p];
        const double      size =
          std::max(std::abs(whole.gap), pairs.points[p].position.norm());
        rows_agree &= pairs.points[p].position.distance(
                        reference.points[p].position) <= 1e-12 * size &&
                      same(here.gap, whole.gap, size) &&
                      same(here.length, whole.length, whole.length) &&
                      same(here.reduced_gap, whole.reduced_gap, size) &&
                      same_entries(here.row, whole.row) &&
                      same_entries(here.reduced_row, whole.reduced_row) &&
                      (here.eliminated == numbers::invalid_dof_index
                         ? whole.eliminated == numbers::invalid_dof_index
                         : whole_of.at(here.eliminated) == whole.eliminated) &&
                      here.slave_eliminated == whole.slave_eliminated;
      }
    rows_agree = Utilities::MPI::min(int(rows_agree), comm) == 1;

    // The contact solve on the distributed mesh: the iterative path on the
    // DoF handler's ownership, C's rows from the owned cells, every set's
    // condensed pattern expanded by each rank from its rows, d from the
    // owned cells summed over the ranks, the rigid motions from every
    // dof's owner; the loop of the scene's settings (CG to 1e-12 of |b|).
    TrilinosWrappers::SparsityPattern condensed;
    ActiveSetSolver::make_sparsity_pattern(pattern,
                                           lines,
                                           pairs.rows,
                                           condensed);
    Vector<double> d(dofs.n_dofs());
    assembler.assemble_rhs(dofs, d);
    const RigidModes<dim> modes(dofs,
                                mesh.body_of_cell,
                                std::vector<std::string>(n_bodies, "body"));
    KrylovSettings        krylov;
    krylov.tolerance = 1e-12;
    IterativeContactSystem system(
      condensed,
      [&](const auto &wanted, const auto &add) {
        assembler.assemble_cells(dofs, wanted, add);
      },
      lines,
      pairs.rows,
      modes,
      krylov);
    system.set_rhs(d);
    std::ostringstream    loop_log;
    const ContactSolution solved = problem.contact_solver().solve(
      system, d.linfty_norm(), lines, pairs.rows, modes, {}, loop_log);
    Vector<double> y;
    system.solution(y);
    double solution_difference = 0;
    for (types::global_dof_index i = 0; i < y.size(); ++i)
      solution_difference =
        std::max(solution_difference, std::abs(y(i) - x(whole_of.at(i))));
    const double relative_difference = solution_difference / x.linfty_norm();
    const bool   same_active =
      solved.converged && solved.active == problem.contact().active;

    // The results on the distributed mesh (compute_results over the owned
    // cells and dofs, summed and extremes over the ranks) against the whole
    // run's, to 1e-8 of each quantity's scale (the displacements' bound).
    const Results<dim> whole_results = problem.results_of_solution();
    const Results<dim> results       = compute_results(
      ProblemAccess<dim>{dofs,
                               mesh.body_of_cell,
                               [&](Vector<double> &out, const Vector<double> &in) {
                           system.stiffness_product(out, in);
                         },
                               d,
                               y,
                               problem.materials_of(),
                               problem.boundary_conditions_of(),
                               problem.contact_interfaces_of(),
                               pairs,
                               solved});
    const auto close = [](const double a, const double b, const double scale) {
      return std::abs(a - b) <= 1e-8 * scale;
    };
    const auto close_tensor = [&](const Tensor<1, dim> &a,
                                  const Tensor<1, dim> &b,
                                  const double          scale) {
      return (a - b).norm() <= 1e-8 * scale;
    };
    double force_scale = whole_results.applied_load.norm();
    for (const auto &[id, r] : whole_results.reactions)
      force_scale = std::max(force_scale, r.norm());
    bool results_agree =
      results.n_cells == whole_results.n_cells &&
      results.n_dofs == whole_results.n_dofs &&
      close(results.energy, whole_results.energy, whole_results.energy) &&
      close(results.max_displacement,
            whole_results.max_displacement,
            whole_results.max_displacement) &&
      close_tensor(results.applied_load,
                   whole_results.applied_load,
                   force_scale) &&
      results.equilibrium_residual <= 1e-8 &&
      results.reactions.size() == whole_results.reactions.size() &&
      results.von_mises_max.size() == whole_results.von_mises_max.size() &&
      results.stress_yy_range.size() == whole_results.stress_yy_range.size();
    for (const auto &[id, r] : whole_results.reactions)
      results_agree &= results.reactions.count(id) == 1 &&
                       close_tensor(results.reactions.at(id), r, force_scale);
    double stress_scale = 0;
    for (const auto &[id, v] : whole_results.von_mises_max)
      stress_scale = std::max(stress_scale, v);
    for (const auto &[id, v] : whole_results.von_mises_max)
      results_agree &= results.von_mises_max.count(id) == 1 &&
                       close(results.von_mises_max.at(id), v, stress_scale);
    for (const auto &[id, range] : whole_results.stress_yy_range)
      results_agree &= results.stress_yy_range.count(id) == 1 &&
                       close(results.stress_yy_range.at(id).first,
                             range.first,
                             stress_scale) &&
                       close(results.stress_yy_range.at(id).second,
                             range.second,
                             stress_scale);
    for (unsigned int i = 0; i < whole_results.interfaces.size(); ++i)
      {
        const auto &a = results.interfaces[i], &b = whole_results.interfaces[i];
        results_agree &=
          a.n_active == b.n_active && close(a.force, b.force, force_scale) &&
          close(a.max_pressure, b.max_pressure, b.max_pressure) &&
          close(a.contact_length, b.contact_length, 1.) &&
          close_tensor(a.force_on_slave, b.force_on_slave, force_scale);
      }
    results_agree = Utilities::MPI::min(int(results_agree), comm) == 1;

    // The error estimate's pieces on the distributed mesh: the strain
    // recovery of u (the contact pressures imposed at the slave vertices,
    // and without them) from each rank's cells and ghosts, and the
    // products of u's recovered error with both (each rank's cells, summed
    // over the ranks), against the whole run's: eta_u^2 and the products to
    // 1e-8 of eta_u^2, the indicators' sum to 1e-5 (floats).
    std::vector<SurfaceTraction<dim>> whole_tractions, tractions;
    for (unsigned int q = 0; q < pairs.size(); ++q)
      {
        whole_tractions.push_back({reference.points[q].slave_dofs[0],
                                   reference.points[q].normal,
                                   whole_results.pressure[q]});
        tractions.push_back({pairs.points[q].slave_dofs[0],
                             pairs.points[q].normal,
                             results.pressure[q]});
      }
    const auto error_products = [&](
                                  const DoFHandler<dim>                   &on,
                                  const Vector<double>                    &u,
                                  const std::vector<SurfaceTraction<dim>> &t) {
      const std::vector<RecoveredStrain<dim>> recovered =
        RecoveredStrain<dim>::of(on, {&u, &u}, problem.materials_of(), {t, {}});
      std::vector<RecoveredProduct> products =
        recovered_error_products(on,
                                 u,
                                 recovered[0],
                                 {{&u, &recovered[0]}, {&u, &recovered[1]}},
                                 problem.materials_of(),
                                 true);
      double indicators = 0;
      for (const auto &cell : on.active_cell_iterators())
        if (cell->is_locally_owned())
          indicators += products[1].indicators(cell->active_cell_index());
      return std::make_tuple(products[0].eta_u_squared,
                             products[0].product,
                             products[1].product,
                             indicators);
    };
    const auto [whole_eta, whole_own, whole_cross, whole_indicators] =
      error_products(whole_dofs, x, whole_tractions);
    const auto [eta, own, cross, indicators_here] =
      error_products(dofs, y, tractions);
    const double indicators = Utilities::MPI::sum(indicators_here, comm);
    if (knee_contact::parallel::rank() == 0 &&
        std::getenv("KNEE_CONTACT_TEST_VERBOSE") != nullptr)
      std::cerr << scene << ": eta^2 " << eta << " / " << whole_eta
                << ", products " << own << " / " << whole_own << ", " << cross
                << " / " << whole_cross << ", indicators " << indicators
                << " / " << whole_indicators << ", energy "
                << whole_results.energy << '\n';
    // (Scale: eta^2, at least 1e-16 of the energy: on the patch tests the
    // recovery is exact and eta^2 is round-off, 3e-29 of the energy.)
    const double eta_scale = whole_eta + 1e-16 * whole_results.energy;
    const bool   estimates_agree =
      Utilities::MPI::min(int(close(eta, whole_eta, eta_scale) &&
                              close(own, whole_own, eta_scale) &&
                              close(cross, whole_cross, eta_scale) &&
                              std::abs(indicators - whole_indicators) <=
                                1e-5 * (whole_indicators +
                                        1e-16 * whole_results.energy)),
                          comm) == 1;
    const auto n_owned =
      Utilities::MPI::sum(static_cast<unsigned int>(owned.n_elements()), comm);
    if (knee_contact::parallel::rank() == 0)
      std::cout << scene << ": " << n_owned << " rows owned of "
                << dofs.n_dofs() << " (whole: " << x.size() << ")\n"
                << "  C x on the distributed mesh against the whole mesh's: "
                << (difference <= 1e-12 * largest ? "equal" : "DIFFERENT")
                << " to 1e-12 of max |C x|; x^T C x "
                << (std::abs(energy - x_C_x) <= 1e-12 * std::abs(x_C_x)
                      ? "equal"
                      : "DIFFERENT")
                << " to 1e-12\n  Gamma_u and Gamma_o lines ("
                << whole_lines.n_constraints() << ") on the distributed mesh: "
                << (lines_agree ? "those of the whole mesh" : "DIFFERENT")
                << "\n  contact rows (" << reference.size()
                << ") on the distributed mesh: "
                << (rows_agree ? "those of the whole mesh" : "DIFFERENT")
                << "\n  contact solve on the distributed mesh (iterative): "
                << (same_active ? "the whole mesh's active set"
                                : "ANOTHER ACTIVE SET")
                << ", displacements "
                << (relative_difference <= 1e-8 ? "equal" : "DIFFERENT")
                << " to 1e-8 of max |u|\n  results on the distributed mesh ("
                << whole_results.reactions.size() << " reactions, "
                << whole_results.von_mises_max.size() << " materials): "
                << (results_agree ? "the whole run's" : "DIFFERENT")
                << " to 1e-8\n  strain recovery and error products on the "
                   "distributed mesh: "
                << (estimates_agree ? "the whole run's" : "DIFFERENT")
                << " to 1e-8" << std::endl;
    if (knee_contact::parallel::rank() == 0 &&
        std::getenv("KNEE_CONTACT_TEST_VERBOSE") != nullptr)
      std::cerr << scene
                << ": max |u - u_whole| / max |u| = " << relative_difference
                << ", " << solved.n_iterations << " active-set iterations\n";
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<3>("../scenes/contact_patch_3d_tet.prm");
  check<3>("../scenes/contact_patch_3d_tet_rotated.prm");
  check<3>("qp_scene_3d.prm");
  check<3>("../scenes/hertz_sphere_3d_small.prm");
  check<2>("qp_scene.prm");
}
