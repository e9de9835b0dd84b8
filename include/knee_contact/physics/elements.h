#ifndef knee_contact_elements_h
#define knee_contact_elements_h

#include <deal.II/base/quadrature.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe.h>
#include <deal.II/fe/mapping.h>
#include <deal.II/grid/reference_cell.h>
#include <deal.II/grid/tria.h>

#include <memory>
#include <string>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The element kinds of a mesh. knee_contact solves on meshes of one kind:
   * bilinear Q1 on quadrilaterals (FE_Q(1)^dim, MappingQ1, Gauss rules) or
   * the seed's linear P1 on triangles (FE_SimplexP(1)^dim, MappingFE,
   * Gauss-simplex rules). A mixed mesh has its triangles split into
   * quadrilaterals by MeshInput, because deal.II 9.4's no-normal-flux
   * constraints and Kelly estimator take one Mapping for all cells (see the
   * README's element section).
   */
  namespace elements
  {
    /**
     * The one kind of cell of @p triangulation (a mesh of two kinds is an
     * internal error here: MeshInput splits such meshes).
     */
    template <int dim>
    ReferenceCell
    cell_kind(const Triangulation<dim> &triangulation);

    /**
     * The displacement element for cells of kind @p kind: FE_Q(1)^dim or
     * FE_SimplexP(1)^dim.
     */
    template <int dim>
    std::unique_ptr<FiniteElement<dim>>
    displacement_element(const ReferenceCell &kind);

    /**
     * Renumber @p dof_handler's dofs (its locally owned ones, within the
     * same indices) vertex by vertex, the vertices in reverse Cuthill-McKee
     * order of the graph of their cells, each vertex's dim components kept
     * together and in order (the node blocks Trilinos ML's "PDE
     * equations" assumes). The order deal.II's distribute_dofs() leaves is
     * the mesh file's cell order, which a mesher need not keep local.
     */
    template <int dim>
    void
    renumber_vertex_wise(DoFHandler<dim> &dof_handler);

    /**
     * "Q1" or "P1", as in summary.json.
     */
    std::string
    name(const ReferenceCell &kind);

    /**
     * The linear mapping of the cells of @p dof_handler's element.
     */
    template <int dim>
    inline const Mapping<dim> &
    mapping(const DoFHandler<dim> &dof_handler)
    {
      return dof_handler.get_fe()
        .reference_cell()
        .template get_default_linear_mapping<dim, dim>();
    }

    /**
     * Gauss rule with @p n points per direction on the cells of
     * @p dof_handler (QGauss or QGaussSimplex).
     */
    template <int dim>
    inline Quadrature<dim>
    cell_quadrature(const DoFHandler<dim> &dof_handler, const unsigned int n)
    {
      return dof_handler.get_fe()
        .reference_cell()
        .template get_gauss_type_quadrature<dim>(n);
    }

    /**
     * Gauss rule with @p n points per direction on the faces of the cells
     * of @p dof_handler (QGauss on lines and quadrilaterals, QGaussSimplex
     * on the triangles of tetrahedra).
     */
    template <int dim>
    inline Quadrature<dim - 1>
    face_quadrature(const DoFHandler<dim> &dof_handler, const unsigned int n)
    {
      return dof_handler.get_fe()
        .reference_cell()
        .face_reference_cell(0)
        .template get_gauss_type_quadrature<dim - 1>(n);
    }
  } // namespace elements
} // namespace knee_contact

#endif
