#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/recovery.h>

#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/fe/fe_values.h>

#include <map>
#include <utility>
#include <vector>

namespace knee_contact
{
  template <int dim>
  double
  recovered_energy_error(const DoFHandler<dim> &dof_handler,
                         const Vector<double>  &solution,
                         const Materials<dim>  &materials)
  {
    const FiniteElement<dim>        &fe         = dof_handler.get_fe();
    const ReferenceCell              kind       = fe.reference_cell();
    const unsigned int               n_vertices = kind.n_vertices();
    const FEValuesExtractors::Vector displacement(0);

    // The strain at the vertices of every cell (the nodal rule's points are
    // the vertices in deal.II's order), averaged per (vertex, material).
    std::map<std::pair<unsigned int, types::material_id>,
             std::pair<SymmetricTensor<2, dim>, unsigned int>>
      averages;
    {
      FEValues<dim>                        nodal(elements::mapping(dof_handler),
                          fe,
                          kind.template get_nodal_type_quadrature<dim>(),
                          update_gradients);
      std::vector<SymmetricTensor<2, dim>> strains(n_vertices);
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          nodal.reinit(cell);
          nodal[displacement].get_function_symmetric_gradients(solution,
                                                               strains);
          for (unsigned int v = 0; v < n_vertices; ++v)
            {
              auto &[sum, count] =
                averages[{cell->vertex_index(v), cell->material_id()}];
              sum += strains[v];
              ++count;
            }
        }
    }

    // eta^2: the recovered strain interpolated with the scalar linear
    // shape function of each vertex (component 0 of the vector element).
    FEValues<dim>      fe_values(elements::mapping(dof_handler),
                            fe,
                            elements::cell_quadrature(dof_handler, 2),
                            update_values | update_gradients |
                              update_JxW_values);
    const unsigned int n_q = fe_values.n_quadrature_points;
    std::vector<SymmetricTensor<2, dim>> strains(n_q);
    std::vector<SymmetricTensor<2, dim>> recovered(n_vertices);
    double                               eta_squared = 0;
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        fe_values.reinit(cell);
        fe_values[displacement].get_function_symmetric_gradients(solution,
                                                                 strains);
        const Material<dim> &material = materials[cell->material_id()];
        for (unsigned int v = 0; v < n_vertices; ++v)
          {
            const auto &[sum, count] =
              averages.at({cell->vertex_index(v), cell->material_id()});
            recovered[v] = sum / double(count);
          }
        for (unsigned int q = 0; q < n_q; ++q)
          {
            SymmetricTensor<2, dim> difference = -strains[q];
            for (unsigned int v = 0; v < n_vertices; ++v)
              difference +=
                fe_values.shape_value(fe.component_to_system_index(0, v), q) *
                recovered[v];
            eta_squared +=
              difference * material.stress(difference) * fe_values.JxW(q);
          }
      }
    return eta_squared;
  }

  template double
  recovered_energy_error(const DoFHandler<2> &,
                         const Vector<double> &,
                         const Materials<2> &);
  template double
  recovered_energy_error(const DoFHandler<3> &,
                         const Vector<double> &,
                         const Materials<3> &);
} // namespace knee_contact
