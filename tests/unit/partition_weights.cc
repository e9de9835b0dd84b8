// The partition of a distributed mesh weighted by partition_weights()
// (issue 38): each rank's entries of the condensed system's pattern (every
// active set's, ActiveSetSolver::make_sparsity_pattern() on the distributed
// mesh's rows: the measured reference, independent of the estimate) and
// its rows, against their mean over the ranks, on 2 and 3 ranks. The scene
// is run whole on every rank, its mesh distributed twice: once balancing
// the cells alone (no weights), once with the weights. Asserted for the
// weighted partition: every rank's entries and rows within 10 % of their
// means (the balance the weights are for). Printed for the cells alone,
// the same comparison, which this scene fails: the contact rows widen the
// rows of the surfaces' neighbourhoods (the test can fail). Measured
// (largest / mean entries, rows): two ranks 1.051, 1.028 weighted against
// 1.107, 1.028 for the cells alone; three ranks 1.086, 1.082 against
// 1.160, 1.076. Scene: the Hertz sphere (mortar, 226 rows, 9 249 dofs);
// a smaller one (the contact patch, 672 dofs) has too few rows a rank for
// either partition to hold 10 % on three ranks. Printed by rank 0, the same
// for 2 and 3 ranks; KNEE_CONTACT_TEST_VERBOSE prints the ratios to
// stderr.

#include <knee_contact/base/parallel.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/base/mpi.h>

#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include "run_quietly.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>
#include <string>
#include <utility>

using namespace dealii;
using namespace knee_contact;

namespace
{
  // The largest rank's entries and rows of the condensed pattern, each
  // divided by their mean over the ranks, with the mesh of @p problem
  // distributed by @p weights (none: the cells).
  template <int dim>
  std::pair<double, double>
  imbalance(const ContactProblem<dim> &problem,
            const std::vector<double> &weights)
  {
    const MPI_Comm     comm = knee_contact::parallel::communicator();
    Triangulation<dim> whole;
    whole.copy_triangulation(problem.dof_handler_of().get_triangulation());
    unsigned int                    n_bodies = 0;
    const std::vector<unsigned int> bodies = compute_body_ids(whole, n_bodies);
    DistributedMesh<dim>            mesh;
    distribute_mesh(whole, bodies, n_bodies, weights, mesh);
    DoFHandler<dim> dofs(mesh.triangulation);
    dofs.distribute_dofs(problem.dof_handler_of().get_fe());
    TrilinosWrappers::SparsityPattern pattern;
    make_distributed_pattern(dofs, pattern);
    AffineConstraints<double> lines;
    problem.boundary_conditions_of().make_constraints(dofs, lines);
    const ContactPairs<dim> pairs =
      problem.contact_interfaces_of().make_pairs(dofs, lines, &mesh.vertex_id);
    TrilinosWrappers::SparsityPattern condensed;
    ActiveSetSolver::make_sparsity_pattern(pattern,
                                           lines,
                                           pairs.rows,
                                           condensed);
    const double entries =
      condensed.trilinos_sparsity_pattern().NumMyNonzeros();
    const double rows = dofs.locally_owned_dofs().n_elements();
    const double n    = Utilities::MPI::n_mpi_processes(comm);
    return {Utilities::MPI::max(entries, comm) /
              (Utilities::MPI::sum(entries, comm) / n),
            Utilities::MPI::max(rows, comm) /
              (Utilities::MPI::sum(rows, comm) / n)};
  }

  template <int dim>
  void
  check(const std::string &scene)
  {
    ContactProblem<dim> problem(SOURCE_DIR "/" + scene);
    run_quietly(problem, scene);
    const auto cells = imbalance(problem, {});
    const auto weighted =
      imbalance(problem,
                partition_weights(problem.dof_handler_of().get_triangulation(),
                                  problem.contact_interfaces_of()));
    const auto within = [](const std::pair<double, double> &ratios) {
      return ratios.first <= 1.1 && ratios.second <= 1.1 ? "within"
                                                         : "NOT within";
    };
    if (knee_contact::parallel::rank() == 0)
      std::cout << scene << ": every rank's condensed entries and rows "
                << within(weighted)
                << " 10 % of their means, weighted; balancing the cells "
                   "alone: "
                << within(cells) << std::endl;
    if (knee_contact::parallel::rank() == 0 &&
        std::getenv("KNEE_CONTACT_TEST_VERBOSE") != nullptr)
      std::cerr << scene << ": largest / mean entries, rows: weighted "
                << weighted.first << ", " << weighted.second << "; cells "
                << cells.first << ", " << cells.second << '\n';
  }
} // namespace

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check<3>("../scenes/hertz_sphere_3d_small.prm");
}
