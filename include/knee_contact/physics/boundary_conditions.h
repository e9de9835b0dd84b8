#ifndef knee_contact_boundary_conditions_h
#define knee_contact_boundary_conditions_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/component_mask.h>

#include <memory>
#include <set>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The seed's boundary parts (its eqs. (2)-(3)) by boundary id:
   * Gamma_u (prescribed displacement u0, some components may be left
   * free), Gamma_tau (traction P, or a pressure p along the inward normal)
   * and Gamma_o (sliding: u.n = 0 and zero tangential traction).
   */
  enum class BoundaryType
  {
    displacement,
    traction,
    pressure,
    sliding
  };

  template <int dim>
  struct BoundaryCondition
  {
    std::string                          name;
    BoundaryType                         type = BoundaryType::displacement;
    std::set<types::boundary_id>         ids;
    ComponentMask                        mask;
    std::unique_ptr<FunctionParser<dim>> function;
    /** The function is written as numbers: the same everywhere. */
    bool constant = false;
  };



  template <int dim>
  class BoundaryConditions
  {
  public:
    /**
     * Declare the subsection "Boundary conditions" with the subsections
     * 'Condition 0' ... 'Condition @p n_conditions - 1', each entry bound to
     * the member it sets.
     */
    void
    add_parameters(ParameterHandler &prm, const unsigned int n_conditions);

    /**
     * After parsing: the conditions from the entries, with the checks the
     * patterns cannot make (an id in one condition only, a component for a
     * displacement, the expressions).
     */
    void
    check_parameters();

    /** 'Number of conditions' as the scene gives it. */
    unsigned int n_conditions = 0;

    /**
     * Throw if a boundary id named in the scene is missing from the mesh.
     */
    void
    check_mesh(const Triangulation<dim> &triangulation) const;

    /**
     * Constraints of Gamma_u and Gamma_o (the seed's eq. (13), first three
     * lines), after the hanging-node constraints of adaptive meshes.
     * Gamma_o uses deal.II's no-normal-flux constraints, which rotate the
     * constraint to the averaged vertex normal on slanted and curved
     * boundaries. Where a vertex lies on Gamma_u and Gamma_o, Gamma_u wins.
     * On a distributed mesh (DistributedMesh) each rank makes the lines of
     * the dofs it owns (its cells and their ghosts hold every face at
     * them) and every rank gathers them all: the lines of a surface's
     * dofs, the same on every rank.
     */
    void
    make_constraints(const DoFHandler<dim>     &dof_handler,
                     AffineConstraints<double> &constraints) const;

    /**
     * Evaluate the tractions and pressures at load parameter @p t from now
     * on (the displacement conditions do not depend on t: they are part of
     * the factorised system).
     */
    void
    set_load_parameter(const double t);

    const std::vector<BoundaryCondition<dim>> &
    conditions() const
    {
      return list;
    }

  private:
    /** One 'Condition k' subsection as the scene wrote it. */
    struct Entry
    {
      std::vector<unsigned int> ids;
      BoundaryType              type = BoundaryType::displacement;
      std::vector<std::string>  components =
        dim == 2 ? std::vector<std::string>{"x", "y"}
                  : std::vector<std::string>{"x", "y", "z"};
      std::string value = dim == 2 ? "0; 0" : "0; 0; 0";
    };
    std::vector<Entry> entries;

    std::vector<BoundaryCondition<dim>> list;
  };
} // namespace knee_contact

#endif
