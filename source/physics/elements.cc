#include <knee_contact/physics/elements.h>

#include <deal.II/fe/fe_q.h>
#include <deal.II/fe/fe_simplex_p.h>
#include <deal.II/fe/fe_system.h>

namespace knee_contact
{
  namespace elements
  {
    template <int dim>
    ReferenceCell
    cell_kind(const Triangulation<dim> &triangulation)
    {
      // MeshInput splits mixed meshes: two kinds here are a bug of the
      // program (exit code 4), not bad input.
      const auto kinds = triangulation.get_reference_cells();
      AssertThrow(kinds.size() == 1, ExcInternalError());
      return kinds[0];
    }



    template <int dim>
    std::unique_ptr<FiniteElement<dim>>
    displacement_element(const ReferenceCell &kind)
    {
      if (kind.is_simplex())
        return std::make_unique<FESystem<dim>>(FE_SimplexP<dim>(1), dim);
      return std::make_unique<FESystem<dim>>(FE_Q<dim>(1), dim);
    }



    std::string
    name(const ReferenceCell &kind)
    {
      return kind.is_simplex() ? "P1" : "Q1";
    }



    template ReferenceCell
    cell_kind(const Triangulation<2> &);
    template ReferenceCell
    cell_kind(const Triangulation<3> &);
    template std::unique_ptr<FiniteElement<2>>
    displacement_element<2>(const ReferenceCell &);
    template std::unique_ptr<FiniteElement<3>>
    displacement_element<3>(const ReferenceCell &);
  } // namespace elements
} // namespace knee_contact
