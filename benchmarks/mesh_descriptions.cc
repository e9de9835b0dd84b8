// Rank 0's descriptions of the distributed mesh (doc/parallel.md, "The
// lines' rows where they are read, and the descriptions in one pass"):
// for a mesh cut into N parts (METIS, GridTools::partition_triangulation),
// deal.II's create_description_from_triangulation() once per part against
// PartDescriptions (one pass over the mesh, then each part from its own
// cells), each part's description made and packed as distribute_mesh()
// sends it. On one process: a description names its rank, the
// communicator is only stored in it (deal.II's check of the rank against
// the communicator's size is a debug-mode assertion). Prints a table to
// stdout: N, deal.II's time, the one pass, the descriptions from it, and
// the packing (the same for both). A benchmark, not a test. Usage:
//   build/mesh_descriptions MESH.msh N [N ...]

#include <knee_contact/mesh/distributed_mesh.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/grid/grid_in.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/grid/tria_description.h>

#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

using namespace dealii;
using namespace knee_contact;

int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  if (argc < 3)
    {
      std::cerr << "usage: mesh_descriptions MESH.msh N [N ...]" << std::endl;
      return 1;
    }
  Triangulation<3> whole;
  {
    GridIn<3> in;
    in.attach_triangulation(whole);
    std::ifstream file(argv[1]);
    if (!file)
      {
        std::cerr << "mesh_descriptions: cannot read " << argv[1] << std::endl;
        return 1;
      }
    in.read_msh(file);
  }
  const MPI_Comm comm = MPI_COMM_SELF;
  std::printf("%u cells\n\n", whole.n_active_cells());
  std::printf("| N | deal.II [s] | one pass [s] | descriptions from it [s] "
              "| packing [s] | bytes sent |\n|---|---|---|---|---|---|\n");
  for (int k = 2; k < argc; ++k)
    {
      const unsigned int ranks = std::stoul(argv[k]);
      GridTools::partition_triangulation(ranks, whole);
      Timer clock;
      for (unsigned int r = 0; r < ranks; ++r)
        {
          const auto description = TriangulationDescription::Utilities::
            create_description_from_triangulation(
              whole,
              comm,
              TriangulationDescription::Settings::default_setting,
              r);
          (void)description;
        }
      const double by_dealii = clock.wall_time();

      clock.restart();
      const PartDescriptions<3> descriptions(whole, ranks);
      const double              pass   = clock.wall_time();
      double                    making = 0, packing = 0, bytes = 0;
      for (unsigned int r = 0; r < ranks; ++r)
        {
          Timer                     step;
          std::vector<unsigned int> vertex_ids;
          const auto                description =
            descriptions.description(r, comm, vertex_ids);
          making += step.wall_time();
          step.restart();
          bytes += Utilities::pack(description, false).size();
          packing += step.wall_time();
        }
      std::printf("| %u | %.2f | %.2f | %.2f | %.2f | %.3g |\n",
                  ranks,
                  by_dealii,
                  pass,
                  making,
                  packing,
                  bytes);
    }
}
