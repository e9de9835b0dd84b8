// The distributed mesh (issue 38) against the whole mesh it is made from
// and against the geometry's exact measures, on 2 and 3 ranks: two bodies
// (a block and a smaller block above it, apart), of triangles and
// quadrilaterals in 2D, tetrahedra and hexahedra in 3D, each with its
// material id and boundary ids by the face's place. Asserted, with the
// tolerance of a sum of cell measures in another order (1e-12 relative):
// - the cells the ranks own add up to the whole mesh's, every rank owns
//   some, and every neighbour of a rank's cell is its own or a ghost;
// - each body's and each material's volume, summed over the cells the
//   ranks own, is the whole mesh's and the exact one;
// - each boundary id's measure (faces of owned cells) is the whole mesh's;
// - every ghost cell carries the body and material id its owner gives it;
// - every vertex a rank holds names the whole mesh's vertex at its place,
//   no two the same;
// - the DoFs of the element (linear, one per vertex and component) are
//   dim times the whole mesh's vertices;
// - parallel::gather_on_every_rank() (one MPI_Allgatherv of numbers) gives
//   every rank the ranks' records in rank order, exactly, where rank r
//   sends r records (rank 0 none) of doubles and of pairs of indices
//   (std::array).
// - PartDescriptions (every rank's description from one pass over the
//   whole mesh) gives each rank the description deal.II's
//   create_description_from_triangulation() gives it (every field; of the
//   manifold ids the entries of the cell's lines and faces), on these
//   meshes with manifold ids set on some cells, faces and lines, for two
//   partitions: one scattering the cells over the ranks (most cells
//   ghosts somewhere), one leaving the middle ranks no cell.
// Printed by rank 0, the same for any number of ranks.

#include <knee_contact/base/parallel.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>

#include <deal.II/base/mpi.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/grid_generator.h>
#include <deal.II/grid/tria_description.h>

#include <array>
#include <cmath>
#include <iostream>
#include <map>
#include <memory>
#include <set>
#include <string>

using namespace dealii;
using namespace knee_contact;

namespace
{
  // A block [0,1]^dim-1 x [0,0.5] (material 1) and [0.1,0.9]^dim-1 x
  // [0.55,1] (material 2); boundary id 10 + 2 axis + side on each body's
  // faces (the bottom of the upper block is 12 + 2 (dim - 1), say).
  template <int dim>
  void
  make_two_blocks(Triangulation<dim> &whole, const bool simplex)
  {
    Point<dim>                lower_a, upper_a, lower_b, upper_b;
    std::vector<unsigned int> cells_a(dim, 4), cells_b(dim, 3);
    for (unsigned int d = 0; d + 1 < dim; ++d)
      {
        upper_a[d] = 1;
        lower_b[d] = 0.1;
        upper_b[d] = 0.9;
      }
    upper_a[dim - 1] = 0.5;
    lower_b[dim - 1] = 0.55;
    upper_b[dim - 1] = 1;
    cells_a[dim - 1] = 2;
    Triangulation<dim> a, b;
    GridGenerator::subdivided_hyper_rectangle(a, cells_a, lower_a, upper_a);
    GridGenerator::subdivided_hyper_rectangle(b, cells_b, lower_b, upper_b);
    for (auto &cell : a.active_cell_iterators())
      cell->set_material_id(1);
    for (auto &cell : b.active_cell_iterators())
      cell->set_material_id(2);
    Triangulation<dim> blocks;
    GridGenerator::merge_triangulations(a, b, blocks);
    if (simplex)
      GridGenerator::convert_hypercube_to_simplex_mesh(blocks, whole);
    else
      whole.copy_triangulation(blocks);
    for (const auto &cell : whole.active_cell_iterators())
      for (const auto &face : cell->face_iterators())
        if (face->at_boundary())
          {
            const bool   upper = cell->material_id() == 2;
            const double lo[2] = {upper ? 0.1 : 0., upper ? 0.55 : 0.};
            const double hi[2] = {upper ? 0.9 : 1., upper ? 1. : 0.5};
            for (unsigned int d = 0; d < dim; ++d)
              {
                const bool   vertical = d + 1 == dim;
                const double x        = face->center()[d];
                if (std::abs(x - lo[vertical]) < 1e-9)
                  face->set_boundary_id(10 + 2 * d);
                else if (std::abs(x - hi[vertical]) < 1e-9)
                  face->set_boundary_id(11 + 2 * d);
              }
          }
  }

  struct Measures
  {
    std::map<unsigned int, double> body, material, boundary;
  };

  template <int dim>
  Measures
  measures(const Triangulation<dim>        &tria,
           const std::vector<unsigned int> &body_of_cell)
  {
    Measures m;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          m.body[body_of_cell[cell->active_cell_index()]] += cell->measure();
          m.material[cell->material_id()] += cell->measure();
          for (const auto &face : cell->face_iterators())
            if (face->at_boundary())
              m.boundary[face->boundary_id()] += face->measure();
        }
    return m;
  }

  bool
  close(const double a, const double b)
  {
    return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b));
  }

  std::string
  compare(const std::map<unsigned int, double> &whole,
          const std::map<unsigned int, double> &mine,
          const MPI_Comm                        comm)
  {
    bool same = true;
    for (const auto &[id, value] : whole)
      {
        const auto   it = mine.find(id);
        const double sum =
          Utilities::MPI::sum(it == mine.end() ? 0. : it->second, comm);
        same &= close(sum, value);
      }
    // No id the whole mesh does not have.
    for (const auto &part : Utilities::MPI::all_gather(comm, mine))
      for (const auto &[id, value] : part)
        same &= whole.count(id) == 1;
    return same ? "equal" : "DIFFERENT";
  }

  template <int dim>
  void
  check(const bool simplex)
  {
    const MPI_Comm     comm = knee_contact::parallel::communicator();
    Triangulation<dim> whole;
    make_two_blocks(whole, simplex);
    unsigned int                    n_bodies = 0;
    const std::vector<unsigned int> whole_body =
      compute_body_ids(whole, n_bodies);
    const Measures reference = measures(whole, whole_body);

    // distribute_mesh() clears rank 0's mesh: a copy goes in.
    Triangulation<dim> given;
    given.copy_triangulation(whole);
    DistributedMesh<dim> mesh;
    distribute_mesh(given, whole_body, n_bodies, {}, mesh);
    const bool released =
      Utilities::MPI::broadcast(comm, given.n_cells() == 0, 0);
    const auto        &tria  = mesh.triangulation;
    const Measures     mine  = measures(tria, mesh.body_of_cell);
    const unsigned int owned = tria.n_locally_owned_active_cells();
    // The ghost layer: every neighbour of an owned cell is here.
    bool layer = true;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int f : cell->face_indices())
          if (!cell->at_boundary(f))
            layer &= cell->neighbor(f)->is_locally_owned() ||
                     cell->neighbor(f)->is_ghost();
    // Every ghost's body and material as its owner gives them.
    std::map<std::string, std::pair<unsigned int, unsigned int>> of_owned;
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_locally_owned())
        of_owned[cell->id().to_string()] = {
          mesh.body_of_cell[cell->active_cell_index()], cell->material_id()};
    bool       ghosts_agree = true;
    const auto all_owned    = Utilities::MPI::all_gather(comm, of_owned);
    for (const auto &cell : tria.active_cell_iterators())
      if (cell->is_ghost())
        {
          const auto &of_owner =
            all_owned[cell->subdomain_id()].at(cell->id().to_string());
          ghosts_agree &=
            of_owner.first == mesh.body_of_cell[cell->active_cell_index()] &&
            of_owner.second == cell->material_id();
        }

    // Every vertex here names the whole mesh's vertex at its place, and
    // no two the same.
    bool                   ids_agree = true;
    std::set<unsigned int> ids;
    for (unsigned int v = 0; v < tria.n_vertices(); ++v)
      if (tria.get_used_vertices()[v])
        {
          const unsigned int id = mesh.vertex_id[v];
          ids_agree &= id < whole.n_vertices() &&
                       whole.get_vertices()[id] == tria.get_vertices()[v] &&
                       ids.insert(id).second;
        }
    ids_agree = Utilities::MPI::min(int(ids_agree), comm) == 1;

    std::unique_ptr<FiniteElement<dim>> fe;
    if (simplex)
      fe = std::make_unique<FESystem<dim>>(FE_SimplexP<dim>(1), dim);
    else
      fe = std::make_unique<FESystem<dim>>(FE_Q<dim>(1), dim);
    DoFHandler<dim> dofs(tria);
    dofs.distribute_dofs(*fe);

    const double       upper     = dim == 2 ? 0.8 * 0.45 : 0.8 * 0.8 * 0.45;
    const double       lower     = 0.5;
    const unsigned int min_owned = Utilities::MPI::min(owned, comm);
    const bool         has_layer = Utilities::MPI::min(int(layer), comm) == 1;
    const unsigned int sum_owned = Utilities::MPI::sum(owned, comm);
    const bool        agree = Utilities::MPI::min(int(ghosts_agree), comm) == 1;
    const std::string bodies = compare(reference.body, mine.body, comm);
    const std::string material =
      compare(reference.material, mine.material, comm);
    const std::string boundary =
      compare(reference.boundary, mine.boundary, comm);
    if (knee_contact::parallel::rank() == 0)
      std::cout << dim << "D " << (simplex ? "simplex" : "hypercube")
                << ": cells owned " << sum_owned << " of "
                << whole.n_active_cells() << ", every rank owns some "
                << (min_owned > 0 ? "yes" : "NO")
                << ", owned cells' neighbours owned or ghosts "
                << (has_layer ? "yes" : "NO") << "\n  bodies " << n_bodies
                << " " << bodies << ", volumes exact "
                << (close(reference.material.at(1), lower) &&
                        close(reference.material.at(2), upper)
                      ? "yes"
                      : "NO")
                << ", materials " << material << ", boundary ids "
                << reference.boundary.size() << " " << boundary
                << "\n  ghosts' bodies and materials those of their owners "
                << (agree ? "yes" : "NO") << ", vertices name the whole mesh's "
                << (ids_agree ? "yes" : "NO") << "\n  dofs " << dofs.n_dofs()
                << (dofs.n_dofs() == dim * whole.n_vertices() ? " = " : " != ")
                << "dim x vertices, rank 0's whole mesh released "
                << (released ? "yes" : "NO") << std::endl;
  }
} // namespace

namespace
{
  template <int dim>
  bool
  same_description(const TriangulationDescription::Description<dim, dim> &a,
                   const TriangulationDescription::Description<dim, dim> &b,
                   const Triangulation<dim>                              &whole)
  {
    if (!(a.coarse_cells == b.coarse_cells &&
          a.coarse_cell_vertices == b.coarse_cell_vertices &&
          a.coarse_cell_index_to_coarse_cell_id ==
            b.coarse_cell_index_to_coarse_cell_id &&
          a.settings == b.settings && a.smoothing == b.smoothing &&
          a.cell_infos.size() == 1 && b.cell_infos.size() == 1 &&
          a.cell_infos[0].size() == a.coarse_cells.size() &&
          b.cell_infos[0].size() == a.coarse_cells.size()))
      return false;
    for (unsigned int i = 0; i < a.coarse_cells.size(); ++i)
      {
        const auto                                      &x = a.cell_infos[0][i];
        const auto                                      &y = b.cell_infos[0][i];
        const typename Triangulation<dim>::cell_iterator cell(
          &whole, 0, a.coarse_cell_index_to_coarse_cell_id[i]);
        bool same = x.id == y.id && x.subdomain_id == y.subdomain_id &&
                    x.level_subdomain_id == y.level_subdomain_id &&
                    x.manifold_id == y.manifold_id &&
                    x.boundary_ids == y.boundary_ids;
        for (const unsigned int l : cell->line_indices())
          same &= x.manifold_line_ids[l] == y.manifold_line_ids[l];
        if (dim == 3)
          for (const unsigned int f : cell->face_indices())
            same &= x.manifold_quad_ids[f] == y.manifold_quad_ids[f];
        if (!same)
          return false;
      }
    return true;
  }

  /**
   * Whether PartTriangulation (constant-time lookup of a coarse cell by
   * its id) made from this rank's @p description has the cells, ids and
   * subdomains of deal.II's fully distributed triangulation (binary search)
   * made from it, and finds every cell from its id as deal.II's does. A
   * collective call.
   */
  template <int dim>
  bool
  same_part(const TriangulationDescription::Description<dim, dim> &description)
  {
    dealii::parallel::fullydistributed::Triangulation<dim> reference(
      description.comm);
    reference.create_triangulation(description);
    PartTriangulation<dim> ours(description.comm);
    ours.create_triangulation(description);
    bool same = reference.n_active_cells() == ours.n_active_cells() &&
                reference.n_cells(0) == ours.n_cells(0);
    auto a = reference.begin_active();
    auto b = ours.begin_active();
    for (; same && a != reference.end(); ++a, ++b)
      {
        same &= a->index() == b->index() &&
                a->is_artificial() == b->is_artificial() &&
                a->subdomain_id() == b->subdomain_id();
        if (same && !a->is_artificial())
          same &= a->id() == b->id() &&
                  ours.create_cell_iterator(a->id()) == b &&
                  reference.create_cell_iterator(a->id()) == a;
      }
    return same;
  }



  template <int dim>
  void
  check_descriptions(const bool simplex)
  {
    const MPI_Comm     comm  = knee_contact::parallel::communicator();
    const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
    Triangulation<dim> whole;
    make_two_blocks(whole, simplex);
    for (const auto &cell : whole.active_cell_iterators())
      {
        if (cell->index() % 5 == 0)
          cell->set_manifold_id(3);
        if (cell->index() % 4 == 1)
          cell->face(0)->set_manifold_id(4);
        if (dim == 3 && cell->index() % 3 == 2)
          cell->line(1)->set_manifold_id(5);
      }
    bool same = true, lookup = true;
    for (unsigned int partition = 0; partition < 2; ++partition)
      {
        for (const auto &cell : whole.active_cell_iterators())
          cell->set_subdomain_id(partition == 0
                                   ? (7 * cell->index() + 3) % ranks
                                   : (cell->index() == 0 ? 0 : ranks - 1));
        const PartDescriptions<dim> descriptions(whole, ranks);
        for (unsigned int r = 0; r < ranks; ++r)
          {
            std::vector<unsigned int> vertex_ids;
            const auto mine = descriptions.description(r, comm, vertex_ids);
            const auto reference = TriangulationDescription::Utilities::
              create_description_from_triangulation(
                whole,
                comm,
                TriangulationDescription::Settings::default_setting,
                r);
            same &= same_description(mine, reference, whole);
            // The vertices' whole indices name the vertices at their place.
            same &= vertex_ids.size() == mine.coarse_cell_vertices.size();
            for (unsigned int v = 0; same && v < vertex_ids.size(); ++v)
              same &= whole.get_vertices()[vertex_ids[v]] ==
                      mine.coarse_cell_vertices[v];
          }
        std::vector<unsigned int> vertex_ids;
        lookup &= same_part(descriptions.description(
          knee_contact::parallel::rank(), comm, vertex_ids));
      }
    lookup = Utilities::MPI::min(int(lookup), comm) == 1;
    if (knee_contact::parallel::rank() == 0)
      std::cout << dim << "D " << (simplex ? "simplex" : "hypercube")
                << ": every rank's description that of deal.II (2 "
                   "partitions) "
                << (same ? "yes" : "NO")
                << ", its part's cells found by id as deal.II finds them "
                << (lookup ? "yes" : "NO") << std::endl;
  }

  void
  check_gather()
  {
    const MPI_Comm     comm  = MPI_COMM_WORLD;
    const unsigned int rank  = Utilities::MPI::this_mpi_process(comm);
    const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
    // Rank r's records: r of them, the k-th r + k / 8 (exact in binary)
    // and the pair (r, k).
    const auto value = [](const unsigned int r, const unsigned int k) {
      return r + k / 8.;
    };
    std::vector<double>                      mine;
    std::vector<std::array<unsigned int, 2>> mine_pairs;
    for (unsigned int k = 0; k < rank; ++k)
      {
        mine.push_back(value(rank, k));
        mine_pairs.push_back({rank, k});
      }
    const auto all = knee_contact::parallel::gather_on_every_rank(comm, mine);
    const auto pairs =
      knee_contact::parallel::gather_on_every_rank(comm, mine_pairs);
    std::vector<double>                      expected;
    std::vector<std::array<unsigned int, 2>> expected_pairs;
    for (unsigned int r = 0; r < ranks; ++r)
      for (unsigned int k = 0; k < r; ++k)
        {
          expected.push_back(value(r, k));
          expected_pairs.push_back({r, k});
        }
    const bool same =
      Utilities::MPI::min(int(all == expected && pairs == expected_pairs),
                          comm) == 1;
    if (rank == 0)
      std::cout << "gather on every rank: " << expected.size()
                << " records in rank order on every rank "
                << (same ? "yes" : "no") << std::endl;
  }
} // namespace



int
main(int argc, char **argv)
{
  Utilities::MPI::MPI_InitFinalize mpi(argc, argv, 1);
  check_gather();
  check<2>(true);
  check<2>(false);
  check<3>(true);
  check<3>(false);
  check_descriptions<2>(true);
  check_descriptions<2>(false);
  check_descriptions<3>(true);
  check_descriptions<3>(false);
}
