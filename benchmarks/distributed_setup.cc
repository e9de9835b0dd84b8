// The set-up on the distributed mesh, step by step (doc/parallel.md, "The
// distributed mesh (begun)"): rank 0 reads a .msh, the mesh is distributed
// (distribute_mesh), then the DoFs, the Gamma_u and Gamma_o lines and the
// contact rows of a scene (its parameters only; its own mesh is not made),
// the Trilinos pattern, and the contact solve on the distributed mesh: the
// iterative path with C's rows from the owned cells, the scene's active-set
// loop. Prints each step's time from the start and resident memory on
// every rank, and the peak, to stderr. A benchmark, not a test. Usage:
//   mpirun -np N build/distributed_setup SCENE.prm MESH.msh

#include <knee_contact/base/parallel.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_in.h>

#include <malloc.h>

#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

using namespace dealii;
using namespace knee_contact;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc != 3)
    {
      std::cerr << "usage: distributed_setup SCENE.prm MESH.msh" << std::endl;
      return 1;
    }
  const MPI_Comm     comm = MPI_COMM_WORLD;
  const unsigned int rank = Utilities::MPI::this_mpi_process(comm);
  ContactProblem<3>  problem(argv[1]);
  Timer              clock;
  const auto         say = [&](const std::string &what) {
    Utilities::System::MemoryStats stats;
    Utilities::System::get_memory_stats(stats);
    std::cerr << "rank " << rank << ": " << what << ", " << clock.wall_time()
              << " s, resident " << stats.VmRSS / 1024. << " MB" << std::endl;
  };

  Triangulation<3>          whole;
  std::vector<unsigned int> bodies;
  unsigned int              n_bodies = 0;
  if (rank == 0)
    {
      GridIn<3>     in(whole);
      std::ifstream file(argv[2]);
      in.read_msh(file);
      bodies = compute_body_ids(whole, n_bodies);
    }
  n_bodies = Utilities::MPI::broadcast(comm, n_bodies, 0);
  say("whole mesh read on rank 0");
  DistributedMesh<3> mesh;
  distribute_mesh(whole, bodies, n_bodies, {}, mesh);
  whole.clear();
  std::vector<unsigned int>().swap(bodies);
  malloc_trim(0);
  say("mesh distributed");
  DoFHandler<3> dofs(mesh.triangulation);
  dofs.distribute_dofs(FESystem<3>(FE_SimplexP<3>(1), 3));
  say("DoFs");
  AffineConstraints<double> lines;
  problem.boundary_conditions_of().make_constraints(dofs, lines);
  say("lines (" + std::to_string(lines.n_constraints()) + ")");
  const ContactPairs<3> pairs =
    problem.contact_interfaces_of().make_pairs(dofs, lines, &mesh.vertex_id);
  say("contact rows (" + std::to_string(pairs.size()) + ")");
  TrilinosWrappers::SparsityPattern pattern;
  make_distributed_pattern(dofs, pattern);
  say("pattern");
  // Every set's condensed pattern, d, the rigid motions, the iterative
  // path (C's rows assembled from the owned cells) and the scene's
  // active-set loop, as unit/distributed_system checks them.
  TrilinosWrappers::SparsityPattern condensed;
  ActiveSetSolver::make_sparsity_pattern(pattern, lines, pairs.rows, condensed);
  pattern.clear();
  say("condensed pattern");
  const ElasticityAssembler<3> assembler(problem.materials_of(),
                                         problem.boundary_conditions_of());
  Vector<double>               d(dofs.n_dofs());
  assembler.assemble_rhs(dofs, d);
  const RigidModes<3> modes(dofs,
                            mesh.body_of_cell,
                            std::vector<std::string>(n_bodies, "body"));
  say("d and rigid motions");
  if (rank == 0)
    std::cerr << "condensed pattern: " << condensed.n_rows() << " rows, "
              << condensed.n_nonzero_elements()
              << " entries; the iterative path's estimate "
              << IterativeContactSystem::estimated_bytes(condensed, false) / 1e6
              << " MB a rank" << std::endl;
  IterativeContactSystem system(
    condensed,
    [&](const auto &wanted, const auto &add) {
      assembler.assemble_cells(dofs, wanted, add);
    },
    lines,
    pairs.rows,
    modes,
    problem.contact_solver().krylov_settings());
  say("C's rows assembled");
  system.set_rhs(d);
  std::ostringstream    loop_log;
  const ContactSolution solved = problem.contact_solver().solve(
    system, d.linfty_norm(), lines, pairs.rows, modes, {}, loop_log);
  unsigned int n_active = 0;
  for (const bool a : solved.active)
    n_active += a;
  say("contact solved (" + std::to_string(solved.n_iterations) +
      " active-set iterations, " + std::to_string(n_active) + " of " +
      std::to_string(pairs.size()) + " rows active)");
  Vector<double> u;
  system.solution(u);
  Utilities::System::MemoryStats stats;
  Utilities::System::get_memory_stats(stats);
  std::cerr << "rank " << rank << ": peak resident " << stats.VmHWM / 1024.
            << " MB; max |u| " << u.linfty_norm() << " m" << std::endl;
  for (const auto &[name, value] : system.statistics())
    if (rank == 0)
      std::cerr << "  " << name << ": " << value << std::endl;
}
