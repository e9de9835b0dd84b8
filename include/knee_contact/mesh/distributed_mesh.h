#ifndef knee_contact_distributed_mesh_h
#define knee_contact_distributed_mesh_h

#include <deal.II/lac/trilinos_sparsity_pattern.h>

#include <deal.II/distributed/fully_distributed_tria.h>
#include <deal.II/dofs/dof_handler.h>
#include <deal.II/grid/tria.h>
#include <deal.II/grid/tria_description.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * deal.II's parallel::fullydistributed::Triangulation, with a coarse
   * cell's index found from its id in constant time. deal.II 9.4 finds it
   * by a binary search of the rank's (id, index) pairs, and its
   * create_triangulation() sorts the description's cells twice with two
   * such searches per comparison (CellId::to_cell() makes one each): perf
   * of rank 1 over the first 45 s of the 1e6-DoF knee on two ranks put 31 %
   * of its samples (5.9 s) in that search (doc/parallel.md, "Two ranks
   * against one process in interleaved rounds"). Here the ids' set is a bitmap
   * over their range with the count of ids before each 64-bit word: the index
   * of an id is that count plus the set bits below it in its word, 12 bytes per
   * 64 ids of the range (a hash map would take about 40 bytes per id). Made
   * only from descriptions whose coarse cells are in increasing id order, as
   * PartDescriptions makes them (checked).
   */
  template <int dim>
  class PartTriangulation
    : public dealii::parallel::fullydistributed::Triangulation<dim>
  {
  public:
    using dealii::parallel::fullydistributed::Triangulation<dim>::Triangulation;

    void
    create_triangulation(const TriangulationDescription::Description<dim, dim>
                           &description) override;

  private:
    unsigned int
    coarse_cell_id_to_coarse_cell_index(
      const types::coarse_cell_id coarse_cell_id) const override;

    /** The smallest id of this rank's coarse cells. */
    types::coarse_cell_id first_id = 0;
    /** Bit b of word w: the id first_id + 64 w + b is one of this rank's. */
    std::vector<std::uint64_t> id_bits;
    /** The number of this rank's ids below word w's (both empty on a rank
     * without cells). */
    std::vector<unsigned int> ids_before;
  };

  /**
   * A mesh divided over the ranks of a parallel run (issue 38's distributed
   * stage): each rank holds its cells (a METIS partition of the cells) and
   * a layer of ghost cells around them, in deal.II's
   * parallel::fullydistributed::Triangulation, which takes simplices and
   * hexahedra alike (p4est's takes hexahedra only) and cannot be refined:
   * a refined mesh is made whole and distributed again, as the
   * tetrahedral refinement's remeshing already does. Measured at 1e6 DoFs
   * (doc/parallel.md, "The distributed mesh (begun)"): 259 MB of triangulation
   * and 73 MB of DoFs a rank on two ranks, against 484 and 144 whole.
   */
  template <int dim>
  struct DistributedMesh
  {
    /** On the run's ranks (parallel::communicator()). */
    DistributedMesh();

    PartTriangulation<dim> triangulation;
    /**
     * The body of each cell this rank holds (owned or ghost), by
     * active_cell_index(): the numbering of the whole mesh's
     * compute_body_ids(), so that every rank names a body alike.
     */
    std::vector<unsigned int> body_of_cell;
    unsigned int              n_bodies = 0;
    /**
     * The whole mesh's index of each vertex this rank holds (by its index
     * here), so that every rank names a vertex alike (the contact sides'
     * keys); invalid for a vertex a refinement of the whole mesh made.
     */
    std::vector<unsigned int> vertex_id;
    /**
     * What distribute_mesh() took on this rank [s]: "partition" and
     * "descriptions" (rank 0 alone: METIS, and making, packing and
     * sending every rank's description, while the others wait for theirs),
     * "part" (each rank making its cells from its description).
     */
    std::map<std::string, double> times;
  };

  /**
   * Every rank's description of its part of a whole mesh of one level
   * whose subdomain ids are a partition into @p n_ranks parts, for
   * parallel::fullydistributed::Triangulation: what deal.II's
   * TriangulationDescription::Utilities::create_description_from_triangulation()
   * gives without a multigrid hierarchy (the same cells, vertices, ids and
   * order: tests/unit/distributed_mesh.cc compares them), but for all ranks
   * from one pass over the mesh. deal.II's makes each rank's with passes
   * over the whole mesh (its cells, their vertices, the user flags), which
   * took rank 0 2.0 s a rank at 1e6 DoFs and grows as the ranks times the
   * mesh (doc/parallel.md, "The model of the distributed mesh"). The
   * constructor finds each rank's cells (those with a vertex of a cell it
   * owns); description() makes one rank's, in time of its cells.
   */
  template <int dim>
  class PartDescriptions
  {
  public:
    PartDescriptions(const Triangulation<dim> &whole,
                     const unsigned int        n_ranks);

    /** Rank @p rank's description on @p comm, and in @p vertex_ids the
     * whole mesh's index of each of its vertices. */
    TriangulationDescription::Description<dim, dim>
    description(const unsigned int         rank,
                const MPI_Comm             comm,
                std::vector<unsigned int> &vertex_ids) const;

    /** The whole mesh's indices of rank @p rank's cells, owned and ghost,
     * in increasing order (the description's order). */
    const std::vector<unsigned int> &
    cells(const unsigned int rank) const;

  private:
    const Triangulation<dim>              &whole;
    std::vector<std::vector<unsigned int>> cells_of_rank;
  };

  /**
   * Divide rank 0's whole, checked mesh @p whole and its bodies
   * @p whole_body_of_cell (by active_cell_index(); @p n_bodies of them)
   * over the ranks of the run: rank 0 partitions the cells
   * (METIS on the cells' face graph, balancing the number of cells, or
   * given @p weights by active_cell_index() both the vertices each rank
   * holds and the sum of its cells' weights; this sets @p whole's
   * subdomain ids), makes each rank's description (its cells, their ghost
   * layer and the coarse cells they descend from, with material, boundary
   * and manifold ids) and sends it; every rank makes its part of the mesh
   * from it. Rank 0's @p whole is cleared once the descriptions are made,
   * before its part is (a DoFHandler on it clears itself with it); the
   * other ranks' @p whole and @p whole_body_of_cell are not read. A
   * collective call.
   */
  template <int dim>
  void
  distribute_mesh(Triangulation<dim>              &whole,
                  const std::vector<unsigned int> &whole_body_of_cell,
                  const unsigned int               n_bodies,
                  std::vector<double>              weights,
                  DistributedMesh<dim>            &mesh);

  /**
   * C's sparsity pattern on a distributed mesh's DoFs @p dof_handler:
   * this rank's rows (its owned dofs, columns among its relevant ones), from
   * the cells it owns (the entries of a ghost's rows are sent to their
   * owners). A collective call.
   */
  template <int dim>
  void
  make_distributed_pattern(const DoFHandler<dim>             &dof_handler,
                           TrilinosWrappers::SparsityPattern &pattern);
} // namespace knee_contact

#endif
