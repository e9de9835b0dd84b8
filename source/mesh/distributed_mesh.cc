#include <knee_contact/base/parallel.h>
#include <knee_contact/mesh/distributed_mesh.h>

#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/tria_description.h>

#include <metis.h>

#include <algorithm>
#include <array>
#include <bitset>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <new>
#include <tuple>
#include <utility>

namespace knee_contact
{
  namespace
  {
    /** A rank's part: its description, the bodies of its coarse cells and
     * the whole mesh's indices of its coarse vertices, in the description's
     * order. */
    template <int dim>
    using MeshPart = std::tuple<TriangulationDescription::Description<dim, dim>,
                                std::vector<unsigned int>,
                                std::vector<unsigned int>>;



    /**
     * Set @p whole's subdomain ids to a partition of its cells into
     * @p n_parts parts of about equal size (the number of cells; given
     * @p weights by active_cell_index(), both the cells' shares of the
     * vertices and the weights' sum), with few faces between parts:
     * METIS on the cells' face graph, as deal.II's
     * GridTools::partition_triangulation() does (recursive bisection up to
     * 8 parts, k-way beyond, as its SparsityTools::partition() chooses),
     * but with the graph in METIS's two arrays: deal.II builds it as a
     * DynamicSparsityPattern and copies it twice, which took rank 0 187 MB
     * above the whole mesh at 2e6 tetrahedra (doc/parallel.md). @p whole
     * has one level (distribute() flattens a refined mesh).
     */
    template <int dim>
    void
    partition_cells(Triangulation<dim>        &whole,
                    const std::vector<double> &weights,
                    const unsigned int         n_parts)
    {
      AssertThrow(whole.n_levels() == 1, ExcInternalError());
      const unsigned int n_cells = whole.n_active_cells();
      std::vector<idx_t> part(n_cells, 0);
      if (n_parts > 1 && n_cells <= n_parts)
        // More ranks than cells: a cell each, the other ranks none (METIS
        // wants more vertices than parts).
        for (unsigned int c = 0; c < n_cells; ++c)
          part[c] = c;
      else if (n_parts > 1)
        {
          std::vector<idx_t> xadj(n_cells + 1, 0);
          std::vector<idx_t> adjncy;
          adjncy.reserve(std::size_t(n_cells) *
                         whole.begin_active()->n_faces());
          for (const auto &cell : whole.active_cell_iterators())
            {
              for (const unsigned int f : cell->face_indices())
                if (!cell->at_boundary(f))
                  adjncy.push_back(cell->neighbor(f)->active_cell_index());
              xadj[cell->active_cell_index() + 1] = adjncy.size();
            }
          // With weights, two constraints: the cells' shares of the
          // vertices (the rows) and their weights, each scaled to a mean of
          // 100 (METIS takes integers), their sums within idx_t.
          std::vector<idx_t> vertex_weights;
          idx_t              n_constraints = 1;
          if (!weights.empty())
            {
              AssertThrow(weights.size() == n_cells, ExcInternalError());
              std::vector<unsigned int> cells_at(whole.n_vertices(), 0);
              for (const auto &cell : whole.active_cell_iterators())
                for (const unsigned int v : cell->vertex_indices())
                  ++cells_at[cell->vertex_index(v)];
              std::vector<double> rows(n_cells, 0);
              for (const auto &cell : whole.active_cell_iterators())
                for (const unsigned int v : cell->vertex_indices())
                  rows[cell->active_cell_index()] +=
                    1. / cells_at[cell->vertex_index(v)];
              const std::array<const std::vector<double> *, 2> columns = {
                {&rows, &weights}};
              std::array<double, 2> scale;
              for (unsigned int k = 0; k < 2; ++k)
                {
                  double sum = 0;
                  for (const double w : *columns[k])
                    sum += w;
                  AssertThrow(sum > 0 && std::isfinite(sum),
                              ExcInternalError());
                  scale[k] = std::min(100. * n_cells, 1e9) / sum;
                }
              for (unsigned int c = 0; c < n_cells; ++c)
                for (unsigned int k = 0; k < 2; ++k)
                  vertex_weights.push_back(
                    std::max<idx_t>(1,
                                    std::lround((*columns[k])[c] * scale[k])));
              n_constraints = 2;
            }
          idx_t options[METIS_NOPTIONS];
          METIS_SetDefaultOptions(options);
          options[METIS_OPTION_NUMBERING] = 0;
          idx_t      n_vertices = n_cells, parts = n_parts, cut = 0;
          const auto method =
            n_parts <= 8 ? METIS_PartGraphRecursive : METIS_PartGraphKway;
          const int status =
            method(&n_vertices,
                   &n_constraints,
                   xadj.data(),
                   adjncy.empty() ? nullptr : adjncy.data(),
                   vertex_weights.empty() ? nullptr : vertex_weights.data(),
                   nullptr,
                   nullptr,
                   &parts,
                   nullptr,
                   nullptr,
                   options,
                   &cut,
                   part.data());
          if (status == METIS_ERROR_MEMORY)
            throw std::bad_alloc();
          AssertThrow(status == METIS_OK,
                      ExcMessage("METIS failed to partition the mesh's " +
                                 std::to_string(n_cells) + " cells into " +
                                 std::to_string(n_parts) + " parts"));
        }
      for (const auto &cell : whole.active_cell_iterators())
        cell->set_subdomain_id(part[cell->active_cell_index()]);
    }
  } // namespace



  template <int dim>
  void
  PartTriangulation<dim>::create_triangulation(
    const TriangulationDescription::Description<dim, dim> &description)
  {
    const std::vector<types::coarse_cell_id> &ids =
      description.coarse_cell_index_to_coarse_cell_id;
    AssertThrow(std::adjacent_find(ids.begin(),
                                   ids.end(),
                                   std::greater_equal<>()) == ids.end(),
                ExcMessage("a mesh part's coarse cells are not in increasing "
                           "order of their ids"));
    first_id = ids.empty() ? 0 : ids.front();
    const std::size_t n_words =
      ids.empty() ? 0 : (ids.back() - first_id) / 64 + 1;
    id_bits.assign(n_words, 0);
    ids_before.assign(n_words, 0);
    for (const types::coarse_cell_id id : ids)
      id_bits[(id - first_id) / 64] |= std::uint64_t(1)
                                       << ((id - first_id) % 64);
    for (std::size_t w = 1; w < n_words; ++w)
      ids_before[w] =
        ids_before[w - 1] + std::bitset<64>(id_bits[w - 1]).count();
    dealii::parallel::fullydistributed::Triangulation<
      dim>::create_triangulation(description);
  }



  template <int dim>
  unsigned int
  PartTriangulation<dim>::coarse_cell_id_to_coarse_cell_index(
    const types::coarse_cell_id id) const
  {
    // A rank without cells holds deal.II's one dummy cell, of the invalid
    // id.
    if (id_bits.empty())
      return id == numbers::invalid_coarse_cell_id
               ? 0
               : numbers::invalid_unsigned_int;
    if (id < first_id || (id - first_id) / 64 >= id_bits.size())
      return numbers::invalid_unsigned_int;
    const std::size_t   w    = (id - first_id) / 64;
    const std::uint64_t mask = std::uint64_t(1) << ((id - first_id) % 64);
    if ((id_bits[w] & mask) == 0)
      return numbers::invalid_unsigned_int;
    return ids_before[w] + std::bitset<64>(id_bits[w] & (mask - 1)).count();
  }



  template <int dim>
  PartDescriptions<dim>::PartDescriptions(const Triangulation<dim> &whole,
                                          const unsigned int        n_ranks)
    : whole(whole)
    , cells_of_rank(n_ranks)
  {
    AssertThrow(whole.n_levels() == 1, ExcInternalError());
    // deal.II also joins the vertices of periodic faces, which no mesh
    // here has.
    AssertThrow(whole.get_periodic_face_map().empty(), ExcInternalError());
    // The ranks owning a cell at each vertex: the first one in an array,
    // any further one as a pair (vertex, rank), sorted (only the vertices
    // at a partition's border have several).
    const unsigned int        none = numbers::invalid_unsigned_int;
    std::vector<unsigned int> first(whole.n_vertices(), none);
    std::vector<std::pair<unsigned int, unsigned int>> further;
    for (const auto &cell : whole.active_cell_iterators())
      {
        const unsigned int rank = cell->subdomain_id();
        AssertThrow(rank < n_ranks, ExcInternalError());
        for (const unsigned int v : cell->vertex_indices())
          {
            const unsigned int vertex = cell->vertex_index(v);
            if (first[vertex] == none)
              first[vertex] = rank;
            else if (first[vertex] != rank)
              further.emplace_back(vertex, rank);
          }
      }
    std::sort(further.begin(), further.end());
    further.erase(std::unique(further.begin(), further.end()), further.end());
    // A cell is each of its vertices' ranks' (deal.II's "locally relevant"
    // cells: owned, or a ghost sharing a vertex with an owned one), in
    // the mesh's order.
    std::vector<unsigned int> ranks;
    for (const auto &cell : whole.active_cell_iterators())
      {
        ranks.clear();
        for (const unsigned int v : cell->vertex_indices())
          {
            const unsigned int vertex = cell->vertex_index(v);
            ranks.push_back(first[vertex]);
            for (auto p = std::lower_bound(further.begin(),
                                           further.end(),
                                           std::make_pair(vertex, 0u));
                 p != further.end() && p->first == vertex;
                 ++p)
              ranks.push_back(p->second);
          }
        std::sort(ranks.begin(), ranks.end());
        ranks.erase(std::unique(ranks.begin(), ranks.end()), ranks.end());
        for (const unsigned int rank : ranks)
          cells_of_rank[rank].push_back(cell->index());
      }
  }



  template <int dim>
  const std::vector<unsigned int> &
  PartDescriptions<dim>::cells(const unsigned int rank) const
  {
    return cells_of_rank.at(rank);
  }



  template <int dim>
  TriangulationDescription::Description<dim, dim>
  PartDescriptions<dim>::description(
    const unsigned int         rank,
    const MPI_Comm             comm,
    std::vector<unsigned int> &vertex_ids) const
  {
    const std::vector<unsigned int> &cells = cells_of_rank.at(rank);
    TriangulationDescription::Description<dim, dim> description;
    description.comm      = comm;
    description.settings  = TriangulationDescription::Settings::default_setting;
    description.smoothing = whole.get_mesh_smoothing();
    // Its vertices in the whole mesh's order, numbered from 0 (by an array
    // over the whole mesh's vertices: a search per vertex took a quarter
    // more time).
    const unsigned int        none = numbers::invalid_unsigned_int;
    std::vector<unsigned int> local(whole.n_vertices(), none);
    vertex_ids.clear();
    for (const unsigned int c : cells)
      {
        const typename Triangulation<dim>::cell_iterator cell(&whole, 0, c);
        for (const unsigned int v : cell->vertex_indices())
          if (local[cell->vertex_index(v)] == none)
            {
              local[cell->vertex_index(v)] = 0;
              vertex_ids.push_back(cell->vertex_index(v));
            }
      }
    std::sort(vertex_ids.begin(), vertex_ids.end());
    for (unsigned int k = 0; k < vertex_ids.size(); ++k)
      local[vertex_ids[k]] = k;
    description.coarse_cell_vertices.reserve(vertex_ids.size());
    for (const unsigned int v : vertex_ids)
      description.coarse_cell_vertices.push_back(whole.get_vertices()[v]);

    description.coarse_cells.reserve(cells.size());
    description.coarse_cell_index_to_coarse_cell_id.reserve(cells.size());
    description.cell_infos.resize(1);
    description.cell_infos[0].reserve(cells.size());
    for (const unsigned int c : cells)
      {
        const typename Triangulation<dim>::cell_iterator cell(&whole, 0, c);
        dealii::CellData<dim> coarse(cell->n_vertices());
        coarse.material_id = cell->material_id();
        coarse.manifold_id = cell->manifold_id();
        for (const unsigned int v : cell->vertex_indices())
          coarse.vertices[v] = local[cell->vertex_index(v)];
        description.coarse_cells.push_back(std::move(coarse));
        description.coarse_cell_index_to_coarse_cell_id.push_back(
          cell->id().get_coarse_cell_id());

        // (The entries of the manifold ids past a simplex's lines and
        // faces are flat, not left undefined as deal.II leaves them.)
        TriangulationDescription::CellData<dim> info{};
        info.manifold_line_ids.fill(numbers::flat_manifold_id);
        info.manifold_quad_ids.fill(numbers::flat_manifold_id);
        info.id = cell->id().template to_binary<dim>();
        for (const unsigned int f : cell->face_indices())
          if (const types::boundary_id id = cell->face(f)->boundary_id();
              id != numbers::internal_face_boundary_id)
            info.boundary_ids.emplace_back(f, id);
        info.manifold_id = cell->manifold_id();
        if (dim >= 2)
          for (const unsigned int l : cell->line_indices())
            info.manifold_line_ids[l] = cell->line(l)->manifold_id();
        if (dim == 3)
          for (const unsigned int f : cell->face_indices())
            info.manifold_quad_ids[f] = cell->face(f)->manifold_id();
        info.subdomain_id       = cell->subdomain_id();
        info.level_subdomain_id = cell->level_subdomain_id();
        description.cell_infos[0].push_back(std::move(info));
      }
    return description;
  }



  template <int dim>
  DistributedMesh<dim>::DistributedMesh()
    : triangulation(parallel::communicator())
  {}



  template <int dim>
  void
  distribute_mesh(Triangulation<dim>              &whole,
                  const std::vector<unsigned int> &whole_body_of_cell,
                  const unsigned int               n_bodies,
                  std::vector<double>              weights,
                  DistributedMesh<dim>            &mesh)
  {
    const MPI_Comm     comm  = mesh.triangulation.get_communicator();
    const unsigned int ranks = Utilities::MPI::n_mpi_processes(comm);
    const bool         first = Utilities::MPI::this_mpi_process(comm) == 0;
    // Rank 0: the partition (METIS on the cells' face graph) and every
    // rank's description, with the bodies (which a description does not
    // carry).
    std::vector<unsigned int> body_of_coarse;
    Timer                     clock;
    if (first)
      {
        partition_cells(whole, weights, ranks);
        std::vector<double>().swap(weights);
        // A body of the whole mesh by coarse cell: every cell of a coarse
        // cell's tree is of its body.
        body_of_coarse.assign(whole.n_cells(0), 0);
        for (const auto &cell : whole.active_cell_iterators())
          {
            auto coarse = cell;
            while (coarse->level() > 0)
              coarse = coarse->parent();
            body_of_coarse[coarse->index()] =
              whole_body_of_cell.at(cell->active_cell_index());
          }
        mesh.times["partition"] = clock.wall_time();
      }
    clock.restart();
    std::unique_ptr<PartDescriptions<dim>> descriptions;
    if (first)
      descriptions = std::make_unique<PartDescriptions<dim>>(whole, ranks);
    const auto part_of = [&](const unsigned int r) {
      MeshPart<dim> part;
      auto &[description, bodies, vertex_ids] = part;
      description = descriptions->description(r, comm, vertex_ids);
      for (const unsigned int c : descriptions->cells(r))
        bodies.push_back(body_of_coarse.at(c));
      return part;
    };
    // Rank 0's own part is made in place after the others' are sent, not
    // packed and unpacked: rank 0 is the last to start its part.
    std::vector<char> bytes =
      parallel::scatter_from_first([&](const unsigned int r) {
        return r == 0 ? std::vector<char>()
                      : Utilities::pack(part_of(r), false);
      });
    MeshPart<dim> part;
    if (first)
      part = part_of(0);
    descriptions.reset();
    // Rank 0 lets go of the whole mesh before it makes its part, so that
    // it never holds both: its mesh phase's peak at 1e6 DoFs on two ranks
    // 1 623 -> 1 486 MB (doc/parallel.md, "The mesh read without GridIn's
    // stream").
    if (first)
      whole.clear();
    // On the other ranks: waiting for its description.
    mesh.times["descriptions"] = clock.wall_time();
    clock.restart();
    if (!first)
      part = Utilities::unpack<MeshPart<dim>>(bytes, false);
    std::vector<char>().swap(bytes);
    const auto &[description, bodies, vertex_ids] = part;
    // The bodies by the coarse cell's id, which every cell's CellId starts
    // with.
    std::map<types::coarse_cell_id, unsigned int> body_of_id;
    for (unsigned int i = 0; i < bodies.size(); ++i)
      body_of_id[description.coarse_cell_index_to_coarse_cell_id[i]] =
        bodies[i];
    mesh.triangulation.create_triangulation(description);
    mesh.n_bodies = n_bodies;
    mesh.body_of_cell.assign(mesh.triangulation.n_active_cells(), 0);
    // A rank without cells holds deal.II's one artificial dummy cell,
    // which has no id.
    for (const auto &cell : mesh.triangulation.active_cell_iterators())
      if (!cell->is_artificial())
        mesh.body_of_cell[cell->active_cell_index()] =
          body_of_id.at(cell->id().get_coarse_cell_id());
    // The mesh keeps the description's vertices in its order (checked, not
    // documented by deal.II); refinement's vertices have no whole index.
    mesh.vertex_id.assign(mesh.triangulation.n_vertices(),
                          numbers::invalid_unsigned_int);
    const auto &points = mesh.triangulation.get_vertices();
    AssertThrow(points.size() >= vertex_ids.size(), ExcInternalError());
    for (unsigned int v = 0; v < vertex_ids.size(); ++v)
      {
        AssertThrow(points[v] == description.coarse_cell_vertices[v],
                    ExcInternalError());
        mesh.vertex_id[v] = vertex_ids[v];
      }
    mesh.times["part"] = clock.wall_time();
  }



  template <int dim>
  void
  make_distributed_pattern(const DoFHandler<dim>             &dof_handler,
                           TrilinosWrappers::SparsityPattern &pattern)
  {
    const MPI_Comm comm  = parallel::communicator();
    const IndexSet owned = dof_handler.locally_owned_dofs();
    IndexSet       relevant;
    DoFTools::extract_locally_relevant_dofs(dof_handler, relevant);
    pattern.reinit(owned, owned, relevant, comm);
    DoFTools::make_sparsity_pattern(dof_handler,
                                    pattern,
                                    AffineConstraints<double>(),
                                    false,
                                    Utilities::MPI::this_mpi_process(comm));
    pattern.compress();
  }



  template class PartTriangulation<2>;
  template class PartTriangulation<3>;
  template class PartDescriptions<2>;
  template class PartDescriptions<3>;
  template struct DistributedMesh<2>;
  template struct DistributedMesh<3>;
  template void
  distribute_mesh(Triangulation<2> &,
                  const std::vector<unsigned int> &,
                  const unsigned int,
                  std::vector<double>,
                  DistributedMesh<2> &);
  template void
  distribute_mesh(Triangulation<3> &,
                  const std::vector<unsigned int> &,
                  const unsigned int,
                  std::vector<double>,
                  DistributedMesh<3> &);
  template void
  make_distributed_pattern(const DoFHandler<2> &,
                           TrilinosWrappers::SparsityPattern &);
  template void
  make_distributed_pattern(const DoFHandler<3> &,
                           TrilinosWrappers::SparsityPattern &);
} // namespace knee_contact
