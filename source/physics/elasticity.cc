#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/elements.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>
#include <deal.II/base/work_stream.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>

namespace knee_contact
{
  namespace
  {
    template <int dim>
    struct ScratchData
    {
      ScratchData(const DoFHandler<dim> &dof_handler)
        : fe_values(elements::mapping(dof_handler),
                    dof_handler.get_fe(),
                    elements::cell_quadrature(dof_handler, 2),
                    update_values | update_gradients |
                      update_quadrature_points | update_JxW_values)
        , fe_values_reduced(elements::mapping(dof_handler),
                            dof_handler.get_fe(),
                            elements::cell_quadrature(dof_handler, 1),
                            update_gradients | update_JxW_values)
        , fe_face_values(elements::mapping(dof_handler),
                         dof_handler.get_fe(),
                         elements::face_quadrature(dof_handler, 2),
                         update_values | update_quadrature_points |
                           update_normal_vectors | update_JxW_values)
      {}

      ScratchData(const ScratchData &other)
        : fe_values(other.fe_values.get_mapping(),
                    other.fe_values.get_fe(),
                    other.fe_values.get_quadrature(),
                    other.fe_values.get_update_flags())
        , fe_values_reduced(other.fe_values_reduced.get_mapping(),
                            other.fe_values_reduced.get_fe(),
                            other.fe_values_reduced.get_quadrature(),
                            other.fe_values_reduced.get_update_flags())
        , fe_face_values(other.fe_face_values.get_mapping(),
                         other.fe_face_values.get_fe(),
                         other.fe_face_values.get_quadrature(),
                         other.fe_face_values.get_update_flags())
      {}

      FEValues<dim>     fe_values;
      FEValues<dim>     fe_values_reduced;
      FEFaceValues<dim> fe_face_values;
    };

    struct CopyData
    {
      FullMatrix<double>                   cell_matrix;
      Vector<double>                       cell_rhs;
      std::vector<types::global_dof_index> dof_indices;
      /** The cell is not wanted (assemble_cells()). */
      bool skipped = false;
    };
  } // namespace



  // Where the cells' contributions go: C and d whole, d alone, or the
  // cell matrices of the wanted cells.
  template <int dim>
  struct ElasticityAssembler<dim>::Sinks
  {
    SparseMatrix<double>                                     *matrix = nullptr;
    Vector<double>                                           *rhs    = nullptr;
    const std::function<bool(const types::global_dof_index)> *wanted = nullptr;
    const std::function<void(const std::vector<types::global_dof_index> &,
                             const FullMatrix<double> &)>    *cells  = nullptr;
  };



  template <int dim>
  ElasticityAssembler<dim>::ElasticityAssembler(
    const Materials<dim>          &materials,
    const BoundaryConditions<dim> &boundary_conditions)
    : materials(materials)
    , boundary_conditions(boundary_conditions)
  {}



  template <int dim>
  void
  ElasticityAssembler<dim>::assemble(const DoFHandler<dim> &dof_handler,
                                     SparseMatrix<double>  &matrix,
                                     Vector<double>        &rhs) const
  {
    matrix = 0;
    rhs.reinit(dof_handler.n_dofs());
    Sinks sinks;
    sinks.matrix = &matrix;
    sinks.rhs    = &rhs;
    assemble(dof_handler, sinks);
  }



  template <int dim>
  void
  ElasticityAssembler<dim>::assemble_rhs(const DoFHandler<dim> &dof_handler,
                                         Vector<double>        &rhs) const
  {
    rhs.reinit(dof_handler.n_dofs());
    Sinks sinks;
    sinks.rhs = &rhs;
    assemble(dof_handler, sinks);
    // A distributed mesh: each rank assembled its cells; every rank takes
    // the whole d (the loop and the results read it whole).
    if (const auto *distributed =
          dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
            &dof_handler.get_triangulation()))
      Utilities::MPI::sum(ArrayView<const double>(rhs.begin(), rhs.size()),
                          distributed->get_communicator(),
                          ArrayView<double>(rhs.begin(), rhs.size()));
  }



  template <int dim>
  void
  ElasticityAssembler<dim>::assemble_cells(
    const DoFHandler<dim>                                    &dof_handler,
    const std::function<bool(const types::global_dof_index)> &wanted,
    const std::function<void(const std::vector<types::global_dof_index> &,
                             const FullMatrix<double> &)>    &add) const
  {
    Sinks sinks;
    sinks.wanted = &wanted;
    sinks.cells  = &add;
    assemble(dof_handler, sinks);
  }



  template <int dim>
  void
  ElasticityAssembler<dim>::assemble(const DoFHandler<dim> &dof_handler,
                                     const Sinks           &sinks) const
  {
    const bool with_matrix = sinks.matrix != nullptr || sinks.cells != nullptr;
    const bool with_rhs    = sinks.rhs != nullptr;

    // a(u, v) = int e(v) : c : e(u) dx and L(v) = int F.v dx + int P.v ds,
    // the seed's eq. (5), cell by cell.
    const auto worker = [this, with_matrix, with_rhs, &sinks](
                          const typename DoFHandler<dim>::active_cell_iterator
                                           &cell,
                          ScratchData<dim> &scratch,
                          CopyData         &copy) {
      // On a distributed mesh (DistributedMesh) a rank assembles the cells
      // it owns, not its ghosts: their owners do (a whole mesh's cells are
      // all owned). A rank without cells has an artificial one, without
      // dofs.
      copy.skipped = !cell->is_locally_owned();
      if (copy.skipped)
        return;
      const FiniteElement<dim> &fe       = cell->get_fe();
      const unsigned int        n        = fe.n_dofs_per_cell();
      const Material<dim>      &material = materials[cell->material_id()];
      copy.dof_indices.resize(n);
      cell->get_dof_indices(copy.dof_indices);
      copy.skipped = (sinks.wanted != nullptr &&
                      std::none_of(copy.dof_indices.begin(),
                                   copy.dof_indices.end(),
                                   [&](const types::global_dof_index i) {
                                     return (*sinks.wanted)(i);
                                   }));
      if (copy.skipped)
        return;
      copy.cell_matrix.reinit(n, n);
      copy.cell_rhs.reinit(n);

      // A linear simplex's strains are constant on it: its one-point rule
      // (fe_values_reduced) integrates the stiffness exactly, with a
      // quarter of the products of the four-point rule a body force
      // F(x) needs (the assembly of the 3D knee at 2.3e5 dofs, one
      // process: 2.85 s with four points, 1.64 with one). A quadrilateral
      // or hexahedron takes the full rule, its volumetric part optionally
      // reduced.
      const bool constant_strain =
        cell->reference_cell().is_simplex() && fe.tensor_degree() == 1;
      const bool body_force = with_rhs && !material.body_force_is_zero;
      const FEValues<dim> &stiffness =
        constant_strain ? scratch.fe_values_reduced : scratch.fe_values;
      if (with_matrix && (constant_strain || material.reduced_volumetric))
        scratch.fe_values_reduced.reinit(cell);
      if ((with_matrix && !constant_strain) || body_force)
        scratch.fe_values.reinit(cell);
      if (with_matrix)
        {
          const double lambda = material.reduced_volumetric && !constant_strain
                                  ? 0.
                                  : material.lambda;
          for (const unsigned int q : stiffness.quadrature_point_indices())
            for (unsigned int i = 0; i < n; ++i)
              {
                const unsigned int   ci = fe.system_to_component_index(i).first;
                const Tensor<1, dim> gi = stiffness.shape_grad(i, q);
                for (unsigned int j = 0; j < n; ++j)
                  {
                    const unsigned int cj =
                      fe.system_to_component_index(j).first;
                    const Tensor<1, dim> gj = stiffness.shape_grad(j, q);
                    // c_ijkl for isotropic material, written per component
                    // pair as in step-8.
                    copy.cell_matrix(i, j) +=
                      (gi[ci] * gj[cj] * lambda +
                       gi[cj] * gj[ci] * material.mu +
                       (ci == cj ? gi * gj * material.mu : 0.)) *
                      stiffness.JxW(q);
                  }
              }
        }
      if (body_force)
        {
          const FEValues<dim> &fev = scratch.fe_values;
          Vector<double>       force(dim);
          for (const unsigned int q : fev.quadrature_point_indices())
            {
              material.body_force->vector_value(fev.quadrature_point(q), force);
              for (unsigned int i = 0; i < n; ++i)
                copy.cell_rhs(i) +=
                  fev.shape_value(i, q) *
                  force(fe.system_to_component_index(i).first) * fev.JxW(q);
            }
        }

      if (with_matrix && material.reduced_volumetric && !constant_strain)
        {
          const FEValues<dim> &fer = scratch.fe_values_reduced;
          for (const unsigned int q : fer.quadrature_point_indices())
            for (unsigned int i = 0; i < n; ++i)
              for (unsigned int j = 0; j < n; ++j)
                copy.cell_matrix(i, j) +=
                  fer.shape_grad(i, q)[fe.system_to_component_index(i).first] *
                  fer.shape_grad(j, q)[fe.system_to_component_index(j).first] *
                  material.lambda * fer.JxW(q);
        }

      for (const unsigned int f : cell->face_indices())
        if (with_rhs && cell->face(f)->at_boundary())
          for (const auto &condition : boundary_conditions.conditions())
            if ((condition.type == BoundaryType::traction ||
                 condition.type == BoundaryType::pressure) &&
                condition.ids.count(cell->face(f)->boundary_id()))
              {
                scratch.fe_face_values.reinit(cell, f);
                const FEFaceValues<dim> &fv = scratch.fe_face_values;
                for (const unsigned int q : fv.quadrature_point_indices())
                  {
                    Tensor<1, dim> traction;
                    if (condition.type == BoundaryType::pressure)
                      traction =
                        -condition.function->value(fv.quadrature_point(q)) *
                        fv.normal_vector(q);
                    else
                      for (unsigned int d = 0; d < dim; ++d)
                        traction[d] =
                          condition.function->value(fv.quadrature_point(q), d);
                    for (unsigned int i = 0; i < n; ++i)
                      copy.cell_rhs(i) +=
                        fv.shape_value(i, q) *
                        traction[fe.system_to_component_index(i).first] *
                        fv.JxW(q);
                  }
              }
    };

    const auto copier = [&sinks](const CopyData &copy) {
      if (copy.skipped)
        return;
      if (sinks.matrix != nullptr)
        sinks.matrix->add(copy.dof_indices, copy.cell_matrix);
      if (sinks.rhs != nullptr)
        sinks.rhs->add(copy.dof_indices, copy.cell_rhs);
      if (sinks.cells != nullptr)
        (*sinks.cells)(copy.dof_indices, copy.cell_matrix);
    };

    WorkStream::run(dof_handler.begin_active(),
                    dof_handler.end(),
                    worker,
                    copier,
                    ScratchData<dim>(dof_handler),
                    CopyData());
  }


  template class ElasticityAssembler<2>;
  template class ElasticityAssembler<3>;
} // namespace knee_contact
