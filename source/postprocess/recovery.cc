#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/recovery.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/work_stream.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace knee_contact
{
  namespace
  {
    // The stiffness tensor of @p material (its stress of each unit strain),
    // to turn a recovered stress back into a strain.
    template <int dim>
    SymmetricTensor<4, dim>
    stiffness(const Material<dim> &material)
    {
      SymmetricTensor<4, dim> c;
      for (unsigned int i = 0; i < dim; ++i)
        for (unsigned int j = i; j < dim; ++j)
          {
            // e_ij = e_ji = 1/2 off the diagonal: C : e = C_..ij.
            SymmetricTensor<2, dim> unit;
            unit[i][j]                           = (i == j ? 1. : 0.5);
            const SymmetricTensor<2, dim> stress = material.stress(unit);
            for (unsigned int k = 0; k < dim; ++k)
              for (unsigned int l = k; l < dim; ++l)
                c[k][l][i][j] = stress[k][l];
          }
      return c;
    }
  } // namespace



  template <int dim>
  RecoveredStrain<dim>::RecoveredStrain(
    const DoFHandler<dim>                   &dof_handler,
    const Vector<double>                    &solution,
    const Materials<dim>                    &materials,
    const std::vector<SurfaceTraction<dim>> &tractions)
  {
    *this = std::move(of(dof_handler, {&solution}, materials, {tractions})[0]);
  }



  template <int dim>
  std::vector<RecoveredStrain<dim>>
  RecoveredStrain<dim>::of(
    const DoFHandler<dim>                                &dof_handler,
    const std::vector<const Vector<double> *>            &solutions,
    const Materials<dim>                                 &materials,
    const std::vector<std::vector<SurfaceTraction<dim>>> &tractions)
  {
    AssertThrow(tractions.size() == solutions.size(), ExcInternalError());
    const unsigned int n_mesh_vertices =
      dof_handler.get_triangulation().n_vertices();
    // (The default constructor is private: built here, moved into place.)
    std::vector<RecoveredStrain<dim>> recovered;
    for (unsigned int i = 0; i < solutions.size(); ++i)
      {
        recovered.push_back(RecoveredStrain<dim>());
        recovered.back().averages.resize(n_mesh_vertices);
      }
    // The strain of each solution at the vertices of every cell (the nodal
    // rule's points are the vertices in deal.II's order), summed per
    // (vertex, material); the (vertex, material) slots are the same for
    // every solution.
    const FiniteElement<dim>              &fe         = dof_handler.get_fe();
    const ReferenceCell                    kind       = fe.reference_cell();
    const unsigned int                     n_vertices = kind.n_vertices();
    std::vector<std::vector<unsigned int>> counts(n_mesh_vertices);
    bool                                   any_traction = false;
    for (const auto &t : tractions)
      any_traction = any_traction || !t.empty();
    std::vector<unsigned int> vertex_of_dof(any_traction ? dof_handler.n_dofs()
                                                         : 0,
                                            numbers::invalid_unsigned_int);
    FEValues<dim>                        nodal(elements::mapping(dof_handler),
                        fe,
                        kind.template get_nodal_type_quadrature<dim>(),
                        update_gradients);
    std::vector<SymmetricTensor<2, dim>> strains(n_vertices);
    const FEValuesExtractors::Vector     displacement(0);
    const unsigned int                   n_cell_dofs = fe.n_dofs_per_cell();
    std::vector<types::global_dof_index> cell_dofs(n_cell_dofs);
    std::vector<SymmetricTensor<2, dim>> shape_strains(n_cell_dofs *
                                                       n_vertices);
    // The (vertex, material) slots and their counts from every cell, in
    // the cells' order (cheap: no strains).
    // A distributed mesh (DistributedMesh): every rank recovers at the
    // vertices of its cells from them and their ghosts (each such vertex's
    // cells are all there), and no sum over the ranks is needed; a ghost's
    // vertices that lie on artificial cells too are averaged short, but no
    // owned cell reads them.
    const bool distributed =
      dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
        &dof_handler.get_triangulation()) != nullptr;
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            const unsigned int vertex = cell->vertex_index(v);
            auto              &here   = recovered[0].averages[vertex];
            unsigned int       k      = 0;
            while (k < here.size() && here[k].first != cell->material_id())
              ++k;
            if (k == here.size())
              {
                for (auto &r : recovered)
                  r.averages[vertex].emplace_back(cell->material_id(),
                                                  SymmetricTensor<2, dim>());
                counts[vertex].push_back(0);
              }
            ++counts[vertex][k];
            if (any_traction)
              vertex_of_dof[cell->vertex_dof_index(v, 0)] = vertex;
          }
    // The strains summed over this rank's share of the cells (under
    // mpirun every rank holds the mesh and the solutions: rank r takes the
    // r-th of N contiguous ranges of active cells), then over the ranks.
    // Measured at 446 206 cells (2.3e5 dofs, five solutions, two ranks):
    // 3.0 s on each rank when each summed every cell; with the products
    // below divided too, the error estimate took 5.6 s instead of 7.7.
    const unsigned int ranks = parallel::n_ranks(), rank = parallel::rank();
    const std::size_t  n_cells =
      dof_handler.get_triangulation().n_active_cells();
    const std::size_t first = n_cells * rank / ranks,
                      end   = n_cells * (rank + 1) / ranks;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        if (distributed ? cell->is_artificial()
                        : cell->active_cell_index() < first ||
                            cell->active_cell_index() >= end)
          continue;
        nodal.reinit(cell);
        cell->get_dof_indices(cell_dofs);
        // The shape functions' strains once per cell, for every solution.
        for (unsigned int j = 0; j < n_cell_dofs; ++j)
          for (unsigned int v = 0; v < n_vertices; ++v)
            shape_strains[j * n_vertices + v] =
              nodal[displacement].symmetric_gradient(j, v);
        for (unsigned int i = 0; i < solutions.size(); ++i)
          {
            std::fill(strains.begin(),
                      strains.end(),
                      SymmetricTensor<2, dim>());
            for (unsigned int j = 0; j < n_cell_dofs; ++j)
              {
                const double value = (*solutions[i])(cell_dofs[j]);
                for (unsigned int v = 0; v < n_vertices; ++v)
                  strains[v] += value * shape_strains[j * n_vertices + v];
              }
            for (unsigned int v = 0; v < n_vertices; ++v)
              {
                auto &here     = recovered[i].averages[cell->vertex_index(v)];
                unsigned int k = 0;
                while (here[k].first != cell->material_id())
                  ++k;
                here[k].second += strains[v];
              }
          }
      }
    if (ranks > 1 && !distributed)
      {
        constexpr unsigned int n_components =
          SymmetricTensor<2, dim>::n_independent_components;
        std::vector<double> sums;
        for (const auto &r : recovered)
          for (const auto &slots : r.averages)
            for (const auto &[id, strain] : slots)
              for (unsigned int c = 0; c < n_components; ++c)
                sums.push_back(strain.access_raw_entry(c));
        Utilities::MPI::sum(sums, parallel::communicator(), sums);
        std::size_t next = 0;
        for (auto &r : recovered)
          for (auto &slots : r.averages)
            for (auto &[id, strain] : slots)
              for (unsigned int c = 0; c < n_components; ++c)
                strain.access_raw_entry(c) = sums[next++];
      }
    for (unsigned int i = 0; i < solutions.size(); ++i)
      {
        for (unsigned int vertex = 0; vertex < n_mesh_vertices; ++vertex)
          for (unsigned int k = 0; k < counts[vertex].size(); ++k)
            recovered[i].averages[vertex][k].second /=
              double(counts[vertex][k]);
        recovered[i].impose(tractions[i], vertex_of_dof, materials);
      }
    return recovered;
  }



  template <int dim>
  void
  RecoveredStrain<dim>::impose(
    const std::vector<SurfaceTraction<dim>> &tractions,
    const std::vector<unsigned int>         &vertex_of_dof,
    const Materials<dim>                    &materials)
  {
    // At a contact vertex sigma* = P sigma P - p n (x) n with P = I - n (x)
    // n: the tangential stress of the average stays, the normal traction
    // is the contact's (a slave vertex belongs to one body, one material
    // there but at a material junction of that body, where each is set).
    std::map<types::material_id, SymmetricTensor<4, dim>> compliances;
    for (const SurfaceTraction<dim> &traction : tractions)
      {
        if (traction.dof >= vertex_of_dof.size() ||
            vertex_of_dof[traction.dof] == numbers::invalid_unsigned_int)
          continue;
        for (auto &[id, strain] : averages[vertex_of_dof[traction.dof]])
          {
            const Material<dim> &material   = materials[id];
            auto                 compliance = compliances.find(id);
            if (compliance == compliances.end())
              compliance =
                compliances.emplace(id, invert(stiffness(material))).first;
            const Tensor<1, dim> &n = traction.normal;
            Tensor<2, dim>        P = unit_symmetric_tensor<dim>();
            P -= outer_product(n, n);
            Tensor<2, dim> stress =
              P * Tensor<2, dim>(material.stress(strain)) * P;
            stress -= traction.pressure * outer_product(n, n);
            strain = compliance->second * symmetrize(stress);
          }
      }
  }



  template <int dim>
  const SymmetricTensor<2, dim> &
  RecoveredStrain<dim>::operator()(const unsigned int       vertex,
                                   const types::material_id material) const
  {
    for (const auto &[id, strain] : averages[vertex])
      if (id == material)
        return strain;
    AssertThrow(false, ExcInternalError());
    return averages[vertex].front().second;
  }



  namespace
  {
    // recovered_error_products()' per-thread buffers (WorkStream copies
    // them; FEValues is not copyable).
    template <int dim>
    struct ProductScratch
    {
      ProductScratch(const DoFHandler<dim> &dof_handler)
        : fe_values(elements::mapping(dof_handler),
                    dof_handler.get_fe(),
                    elements::cell_quadrature(dof_handler, 2),
                    update_values | update_gradients | update_JxW_values)
      {}

      ProductScratch(const ProductScratch &other)
        : fe_values(other.fe_values.get_mapping(),
                    other.fe_values.get_fe(),
                    other.fe_values.get_quadrature(),
                    other.fe_values.get_update_flags())
      {}

      FEValues<dim>                                     fe_values;
      std::vector<types::global_dof_index>              cell_dofs;
      std::vector<SymmetricTensor<2, dim>>              shape_strains;
      std::vector<SymmetricTensor<2, dim>>              strains_u, vertex_u;
      std::vector<std::vector<SymmetricTensor<2, dim>>> strains_z, vertex_z;
    };

    struct ProductCopy
    {
      /** A cell of another rank's share (under mpirun). */
      bool                skip          = false;
      unsigned int        cell          = 0;
      double              eta_u_squared = 0;
      std::vector<double> products;
    };
  } // namespace



  template <int dim>
  std::vector<RecoveredProduct>
  recovered_error_products(const DoFHandler<dim>             &dof_handler,
                           const Vector<double>              &u,
                           const RecoveredStrain<dim>        &recovered_u,
                           const std::vector<Influence<dim>> &influences,
                           const Materials<dim>              &materials,
                           const bool                         with_indicators)
  {
    const FiniteElement<dim> &fe         = dof_handler.get_fe();
    const unsigned int        n_vertices = fe.reference_cell().n_vertices();
    const FEValuesExtractors::Vector displacement(0);
    const unsigned int               n_z         = influences.size();
    const unsigned int               n_cell_dofs = fe.n_dofs_per_cell();

    std::vector<RecoveredProduct> result(n_z);
    double                        eta_u_squared = 0;
    if (with_indicators)
      for (auto &r : result)
        r.indicators.reinit(dof_handler.get_triangulation().n_active_cells());

    // Cell by cell in parallel (WorkStream: the sums in the cells' order,
    // so the result does not depend on the threads); under mpirun each
    // rank sums its share of the cells (as RecoveredStrain::of()), then
    // the ranks' sums are added.
    const unsigned int ranks = parallel::n_ranks(), rank = parallel::rank();
    const std::size_t  n_cells =
      dof_handler.get_triangulation().n_active_cells();
    const std::size_t first = n_cells * rank / ranks,
                      end   = n_cells * (rank + 1) / ranks;
    // A distributed mesh: each rank its own cells.
    const bool distributed =
      dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
        &dof_handler.get_triangulation()) != nullptr;
    const auto worker =
      [&](const typename DoFHandler<dim>::active_cell_iterator &cell,
          ProductScratch<dim>                                  &scratch,
          ProductCopy                                          &copy) {
        copy.skip = distributed ? !cell->is_locally_owned()
                                : cell->active_cell_index() < first ||
                                    cell->active_cell_index() >= end;
        if (copy.skip)
          return;
        FEValues<dim>     &fe_values = scratch.fe_values;
        const unsigned int n_q       = fe_values.n_quadrature_points;
        scratch.cell_dofs.resize(n_cell_dofs);
        scratch.shape_strains.resize(n_cell_dofs * n_q);
        scratch.strains_u.resize(n_q);
        scratch.vertex_u.resize(n_vertices);
        scratch.strains_z.resize(n_z);
        scratch.vertex_z.resize(n_z);
        fe_values.reinit(cell);
        cell->get_dof_indices(scratch.cell_dofs);
        for (unsigned int j = 0; j < n_cell_dofs; ++j)
          for (unsigned int q = 0; q < n_q; ++q)
            scratch.shape_strains[j * n_q + q] =
              fe_values[displacement].symmetric_gradient(j, q);
        // The discrete strains of a solution at the points, from the shape
        // functions' strains computed once per cell.
        const auto strains_of = [&](const Vector<double>                 &x,
                                    std::vector<SymmetricTensor<2, dim>> &e) {
          e.assign(n_q, SymmetricTensor<2, dim>());
          for (unsigned int j = 0; j < n_cell_dofs; ++j)
            {
              const double value = x(scratch.cell_dofs[j]);
              for (unsigned int q = 0; q < n_q; ++q)
                e[q] += value * scratch.shape_strains[j * n_q + q];
            }
        };
        strains_of(u, scratch.strains_u);
        const types::material_id id = cell->material_id();
        for (unsigned int v = 0; v < n_vertices; ++v)
          scratch.vertex_u[v] = recovered_u(cell->vertex_index(v), id);
        for (unsigned int i = 0; i < n_z; ++i)
          {
            strains_of(*influences[i].z, scratch.strains_z[i]);
            scratch.vertex_z[i].resize(n_vertices);
            for (unsigned int v = 0; v < n_vertices; ++v)
              scratch.vertex_z[i][v] =
                (*influences[i].recovered)(cell->vertex_index(v), id);
          }
        const Material<dim> &material = materials[id];
        copy.cell                     = cell->active_cell_index();
        copy.eta_u_squared            = 0;
        copy.products.assign(n_z, 0.);
        for (unsigned int q = 0; q < n_q; ++q)
          {
            // The recovered strains interpolated with the scalar linear
            // shape function of each vertex (component 0 of the vector
            // element), minus the discrete ones.
            SymmetricTensor<2, dim> error_u = -scratch.strains_u[q];
            for (unsigned int v = 0; v < n_vertices; ++v)
              error_u +=
                fe_values.shape_value(fe.component_to_system_index(0, v), q) *
                scratch.vertex_u[v];
            const SymmetricTensor<2, dim> stress_u = material.stress(error_u);
            copy.eta_u_squared += error_u * stress_u * fe_values.JxW(q);
            for (unsigned int i = 0; i < n_z; ++i)
              {
                SymmetricTensor<2, dim> error_z = -scratch.strains_z[i][q];
                for (unsigned int v = 0; v < n_vertices; ++v)
                  error_z +=
                    fe_values.shape_value(fe.component_to_system_index(0, v),
                                          q) *
                    scratch.vertex_z[i][v];
                copy.products[i] += error_z * stress_u * fe_values.JxW(q);
              }
          }
      };
    const auto copier = [&](const ProductCopy &copy) {
      if (copy.skip)
        return;
      eta_u_squared += copy.eta_u_squared;
      for (unsigned int i = 0; i < n_z; ++i)
        {
          result[i].product += copy.products[i];
          if (with_indicators)
            result[i].indicators(copy.cell) = std::abs(copy.products[i]);
        }
    };
    WorkStream::run(dof_handler.begin_active(),
                    dof_handler.end(),
                    worker,
                    copier,
                    ProductScratch<dim>(dof_handler),
                    ProductCopy());
    if (ranks > 1)
      {
        std::vector<double> sums{eta_u_squared};
        for (const auto &r : result)
          sums.push_back(r.product);
        Utilities::MPI::sum(sums, parallel::communicator(), sums);
        eta_u_squared = sums[0];
        for (unsigned int i = 0; i < n_z; ++i)
          result[i].product = sums[1 + i];
        // Each cell's indicator was set by one rank, zero on the others (a
        // distributed mesh's: each rank's own cells, kept where they are).
        if (with_indicators && !distributed)
          for (auto &r : result)
            Utilities::MPI::sum(
              ArrayView<const float>(r.indicators.begin(), r.indicators.size()),
              parallel::communicator(),
              ArrayView<float>(r.indicators.begin(), r.indicators.size()));
      }
    for (auto &r : result)
      r.eta_u_squared = eta_u_squared;
    return result;
  }



#define KNEE_CONTACT_INSTANTIATE(dim)                              \
  template class RecoveredStrain<dim>;                             \
  template std::vector<RecoveredProduct> recovered_error_products( \
    const DoFHandler<dim> &,                                       \
    const Vector<double> &,                                        \
    const RecoveredStrain<dim> &,                                  \
    const std::vector<Influence<dim>> &,                           \
    const Materials<dim> &,                                        \
    const bool);
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
