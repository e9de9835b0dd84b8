#include <knee_contact/refinement.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/grid/grid_refinement.h>
#include <deal.II/numerics/error_estimator.h>

#include <cmath>

namespace knee_contact
{
  void
  Refinement::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    prm.declare_entry("Number of cycles",
                      "1",
                      Patterns::Integer(1, 20),
                      "Solve on this many meshes, refining between them; "
                      "errors and rates are tabulated.");
    prm.declare_entry("Strategy",
                      "global",
                      Patterns::Selection("global|adaptive|compare"),
                      "global: refine every cell; adaptive: refine the cells "
                      "with the largest Kelly error estimate (energy "
                      "weighted); compare: run both sequences and write "
                      "study.csv, study_error_dofs.png and "
                      "study_error_time.png (speed against error).");
    prm.declare_entry("Refine fraction",
                      "0.5",
                      Patterns::Double(0, 1),
                      "Adaptive: refine the cells that together carry this "
                      "fraction of the estimated error (fixed fraction).");
    prm.leave_subsection();
  }



  void
  Refinement::parse_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    n_cycles            = prm.get_integer("Number of cycles");
    const std::string s = prm.get("Strategy");
    strategy            = s == "global"     ? Strategy::global
                          : s == "adaptive" ? Strategy::adaptive
                                            : Strategy::compare;
    refine_fraction     = prm.get_double("Refine fraction");
    prm.leave_subsection();
  }



  void
  Refinement::refine(const Strategy        strategy,
                     Triangulation<2>     &triangulation,
                     const DoFHandler<2>  &dof_handler,
                     const Vector<double> &solution,
                     const Materials      &materials) const
  {
    if (strategy == Strategy::global)
      {
        triangulation.refine_global(1);
        return;
      }
    Vector<float> indicator(triangulation.n_active_cells());
    KellyErrorEstimator<2>::estimate(
      dof_handler, QGauss<1>(2), {}, solution, indicator);
    for (const auto &cell : triangulation.active_cell_iterators())
      indicator(cell->active_cell_index()) *=
        std::sqrt(materials[cell->material_id()].youngs_modulus);
    GridRefinement::refine_and_coarsen_fixed_fraction(triangulation,
                                                      indicator,
                                                      refine_fraction,
                                                      0.);
    triangulation.execute_coarsening_and_refinement();
  }



  std::string
  Refinement::name(const Strategy strategy)
  {
    return strategy == Strategy::global     ? "uniform"
           : strategy == Strategy::adaptive ? "adaptive"
                                            : "compare";
  }
} // namespace knee_contact
