// The set-up on the distributed mesh, step by step (doc/parallel.md, "The
// distributed mesh (begun)"): rank 0 reads a .msh, the mesh is distributed
// (distribute_mesh), then the DoFs, the Gamma_u and Gamma_o lines and the
// contact rows of a scene (its parameters only; its own mesh is not made),
// the Trilinos pattern and C from the owned cells. Prints each step's time
// from the start and resident memory on every rank, to stderr. A benchmark,
// not a test. Usage:
//   mpirun -np N build/distributed_setup SCENE.prm MESH.msh

#include <knee_contact/base/parallel.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/physics/elasticity.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/trilinos_sparse_matrix.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_in.h>

#include <malloc.h>

#include <fstream>
#include <iostream>
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
  distribute_mesh(whole, bodies, n_bodies, mesh);
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
  const IndexSet owned = dofs.locally_owned_dofs();
  IndexSet       relevant;
  DoFTools::extract_locally_relevant_dofs(dofs, relevant);
  TrilinosWrappers::SparsityPattern pattern(owned, owned, relevant, comm);
  DoFTools::make_sparsity_pattern(
    dofs, pattern, AffineConstraints<double>(), false, rank);
  pattern.compress();
  say("pattern");
  TrilinosWrappers::SparseMatrix C;
  C.reinit(pattern);
  ElasticityAssembler<3>(problem.materials_of(),
                         problem.boundary_conditions_of())
    .assemble_cells(
      dofs,
      [](const types::global_dof_index) { return true; },
      [&](const std::vector<types::global_dof_index> &indices,
          const FullMatrix<double>                   &cell_matrix) {
        C.add(indices, cell_matrix);
      });
  C.compress(VectorOperation::add);
  say("C assembled (" + std::to_string(C.memory_consumption() / 1e6) +
      " MB here)");
}
