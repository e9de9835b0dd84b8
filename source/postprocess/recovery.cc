#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/recovery.h>

#include <deal.II/fe/fe_values.h>

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
    : averages(dof_handler.get_triangulation().n_vertices())
  {
    // The strain of the solution at the vertices of every cell (the nodal
    // rule's points are the vertices in deal.II's order), summed per
    // (vertex, material).
    const FiniteElement<dim>              &fe         = dof_handler.get_fe();
    const ReferenceCell                    kind       = fe.reference_cell();
    const unsigned int                     n_vertices = kind.n_vertices();
    std::vector<std::vector<unsigned int>> counts(averages.size());
    std::vector<unsigned int>              vertex_of_dof(tractions.empty()
                                              ? 0
                                              : dof_handler.n_dofs(),
                                            numbers::invalid_unsigned_int);
    FEValues<dim>                        nodal(elements::mapping(dof_handler),
                        fe,
                        kind.template get_nodal_type_quadrature<dim>(),
                        update_gradients);
    std::vector<SymmetricTensor<2, dim>> strains(n_vertices);
    const FEValuesExtractors::Vector     displacement(0);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        nodal.reinit(cell);
        nodal[displacement].get_function_symmetric_gradients(solution, strains);
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            const unsigned int vertex = cell->vertex_index(v);
            auto              &here   = averages[vertex];
            unsigned int       k      = 0;
            while (k < here.size() && here[k].first != cell->material_id())
              ++k;
            if (k == here.size())
              {
                here.emplace_back(cell->material_id(),
                                  SymmetricTensor<2, dim>());
                counts[vertex].push_back(0);
              }
            here[k].second += strains[v];
            ++counts[vertex][k];
            if (!tractions.empty())
              vertex_of_dof[cell->vertex_dof_index(v, 0)] = vertex;
          }
      }
    for (unsigned int vertex = 0; vertex < averages.size(); ++vertex)
      for (unsigned int k = 0; k < averages[vertex].size(); ++k)
        averages[vertex][k].second /= double(counts[vertex][k]);

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



  template <int dim>
  RecoveredProduct
  recovered_error_product(const DoFHandler<dim>      &dof_handler,
                          const Vector<double>       &u,
                          const RecoveredStrain<dim> &recovered_u,
                          const Vector<double>       &z,
                          const RecoveredStrain<dim> &recovered_z,
                          const Materials<dim>       &materials,
                          const bool                  with_indicators)
  {
    const FiniteElement<dim> &fe         = dof_handler.get_fe();
    const unsigned int        n_vertices = fe.reference_cell().n_vertices();
    const FEValuesExtractors::Vector displacement(0);
    const bool same = &u == &z && &recovered_u == &recovered_z;

    FEValues<dim>      fe_values(elements::mapping(dof_handler),
                            fe,
                            elements::cell_quadrature(dof_handler, 2),
                            update_values | update_gradients |
                              update_JxW_values);
    const unsigned int n_q = fe_values.n_quadrature_points;
    std::vector<SymmetricTensor<2, dim>> strains_u(n_q), strains_z(n_q);
    std::vector<SymmetricTensor<2, dim>> vertex_u(n_vertices),
      vertex_z(n_vertices);
    RecoveredProduct result;
    if (with_indicators)
      result.indicators.reinit(
        dof_handler.get_triangulation().n_active_cells());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        fe_values[displacement].get_function_symmetric_gradients(u, strains_u);
        if (!same)
          fe_values[displacement].get_function_symmetric_gradients(z,
                                                                   strains_z);
        const Material<dim> &material = materials[cell->material_id()];
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            vertex_u[v] =
              recovered_u(cell->vertex_index(v), cell->material_id());
            if (!same)
              vertex_z[v] =
                recovered_z(cell->vertex_index(v), cell->material_id());
          }
        double product = 0;
        for (unsigned int q = 0; q < n_q; ++q)
          {
            // The recovered strains interpolated with the scalar linear
            // shape function of each vertex (component 0 of the vector
            // element), minus the discrete ones.
            SymmetricTensor<2, dim> error_u = -strains_u[q];
            SymmetricTensor<2, dim> error_z;
            if (!same)
              error_z = -strains_z[q];
            for (unsigned int v = 0; v < n_vertices; ++v)
              {
                const double phi =
                  fe_values.shape_value(fe.component_to_system_index(0, v), q);
                error_u += phi * vertex_u[v];
                if (!same)
                  error_z += phi * vertex_z[v];
              }
            if (same)
              error_z = error_u;
            const SymmetricTensor<2, dim> stress_u = material.stress(error_u);
            product += error_z * stress_u * fe_values.JxW(q);
            result.eta_u_squared += error_u * stress_u * fe_values.JxW(q);
          }
        result.product += product;
        if (with_indicators)
          result.indicators(cell->active_cell_index()) = std::abs(product);
      }
    return result;
  }



  template <int dim>
  double
  recovered_energy_error(const DoFHandler<dim> &dof_handler,
                         const Vector<double>  &solution,
                         const Materials<dim>  &materials)
  {
    const RecoveredStrain<dim> recovered(dof_handler, solution, materials);
    return recovered_error_product(
             dof_handler, solution, recovered, solution, recovered, materials)
      .eta_u_squared;
  }



#define KNEE_CONTACT_INSTANTIATE(dim)                             \
  template class RecoveredStrain<dim>;                            \
  template RecoveredProduct recovered_error_product(              \
    const DoFHandler<dim> &,                                      \
    const Vector<double> &,                                       \
    const RecoveredStrain<dim> &,                                 \
    const Vector<double> &,                                       \
    const RecoveredStrain<dim> &,                                 \
    const Materials<dim> &,                                       \
    const bool);                                                  \
  template double recovered_energy_error(const DoFHandler<dim> &, \
                                         const Vector<double> &,  \
                                         const Materials<dim> &);
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
