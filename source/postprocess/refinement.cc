#include <knee_contact/base/input.h>
#include <knee_contact/contact/search.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/refinement.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/grid/grid_refinement.h>
#include <deal.II/numerics/error_estimator.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace knee_contact
{
  void
  Refinement::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Refinement");
    prm.add_parameter("Number of cycles",
                      n_cycles,
                      "Solve on this many meshes, refining between them; "
                      "errors and rates are tabulated.",
                      Patterns::Integer(1, 20));
    prm.add_parameter("Number of adaptive cycles",
                      n_adaptive_cycles,
                      "Cycles of the adaptive sequence, which grows more "
                      "slowly than the uniform one; 0: Number of cycles.",
                      Patterns::Integer(0, 30));
    input::add_selection(
      prm,
      "Strategy",
      strategy,
      {{"global", Strategy::global},
       {"adaptive", Strategy::adaptive},
       {"compare", Strategy::compare}},
      "global: refine every cell; adaptive: refine the cells with the "
      "largest Kelly error estimate (energy weighted); compare: run both "
      "sequences and write study.csv, study_error_dofs.png and "
      "study_error_time.png (speed against error).");
    prm.add_parameter("Refine fraction",
                      refine_fraction,
                      "Adaptive: refine the cells that together carry this "
                      "fraction of the estimated error (fixed fraction).",
                      Patterns::Double(0, 1));
    input::add_selection(
      prm,
      "Indicator",
      indicator,
      {{"kelly", Indicator::kelly},
       {"kelly+contact", Indicator::kelly_contact}},
      "Adaptive: kelly, or kelly+contact, which also refines every cell at "
      "the active contact zone (one slave vertex spacing around it), where "
      "the pressure is resolved. Both sides of an interface are refined "
      "together.");
    prm.add_parameter(
      "Target error",
      target_error,
      "0: off. Else the relative error (error bar / value) at which the "
      "run stops refining: it refines by Strategy (global or adaptive) "
      "until the error bar of 'Target quantity' is below this fraction of "
      "its value (from the second mesh on, a bar not flagged as outside "
      "its assumptions; a peak pressure's target refines adaptively by that "
      "pressure's own goal-oriented indicator), at most Number of cycles "
      "(global) or Number of adaptive "
      "cycles (adaptive) meshes, and reports the value with its error bar, "
      "the DoFs and the time.",
      Patterns::Double(0, 1));
    prm.add_parameter(
      "Target quantity",
      target_quantity,
      "The quantity 'Target error' is for: 'peak pressure' (the largest "
      "over the interfaces), 'energy', or one of an interface 'interface "
      "NAME: peak pressure', 'interface NAME: force', 'interface NAME: "
      "contact length' (NAME: Contact/Interface N/Name).",
      Patterns::Anything());
    prm.leave_subsection();
  }



  void
  Refinement::check_parameters()
  {
    if (n_adaptive_cycles == 0)
      n_adaptive_cycles = n_cycles;
    AssertThrow(target_error == 0 || strategy != Strategy::compare,
                ExcMessage("Refinement/Target error needs Refinement/"
                           "Strategy = global or adaptive (compare runs two "
                           "whole sequences)"));
  }



  template <int dim>
  bool
  Refinement::refine(const Strategy            strategy,
                     Triangulation<dim>       &triangulation,
                     const ProblemAccess<dim> &state,
                     const Vector<float>      *goal) const
  {
    const DoFHandler<dim> &dof_handler = state.dof_handler;
    if (strategy == Strategy::global)
      {
        triangulation.refine_global(1);
        return true;
      }
    Vector<float> kelly(triangulation.n_active_cells());
    if (goal != nullptr && goal->size() == kelly.size() && goal->l1_norm() > 0)
      kelly = *goal;
    else
      {
        KellyErrorEstimator<dim>::estimate(
          elements::mapping(dof_handler),
          dof_handler,
          elements::face_quadrature(dof_handler, 2),
          {},
          state.solution,
          kelly);
        for (const auto &cell : triangulation.active_cell_iterators())
          kelly(cell->active_cell_index()) *=
            std::sqrt(state.materials[cell->material_id()].youngs_modulus);
        // The weighted estimate is in units of a(u, u)^1/2. Where it is at
        // round-off, the mesh represents the solution (a linear field on
        // Q1), the indicators are rounding noise, and the cells marked would
        // depend on the order of floating point operations (measured: an
        // exact tetrahedral block refined to 1 626 or 1 591 cells with one
        // or two BLAS threads).
        Vector<double> product(state.solution.size());
        state.stiffness_product(product, state.solution);
        const double energy = state.solution * product;
        if (!(kelly.l2_norm() > round_off_level * std::sqrt(energy)))
          return false;
      }
    GridRefinement::refine_and_coarsen_fixed_fraction(triangulation,
                                                      kelly,
                                                      refine_fraction,
                                                      0.);
    if (indicator == Indicator::kelly_contact)
      {
        // The contact zone: within one slave spacing of an active pair, on
        // either side.
        std::vector<std::pair<Point<dim>, double>> zone;
        const ContactPairs<dim>                   &pairs = state.pairs;
        for (unsigned int p = 0; p < pairs.size(); ++p)
          if (state.contact.active[p])
            zone.emplace_back(pairs.points[p].position,
                              2 * pairs.rows[p].spacing(dim));
        for (const auto &cell : triangulation.active_cell_iterators())
          for (const unsigned int v : cell->vertex_indices())
            for (const auto &[centre, radius] : zone)
              if (cell->vertex(v).distance(centre) <= radius)
                cell->set_refine_flag();
      }
    mark_partners(triangulation, state.interfaces);
    triangulation.execute_coarsening_and_refinement();
    return true;
  }



  template <int dim>
  void
  Refinement::mark_partners(Triangulation<dim>      &triangulation,
                            const ContactInterfaces &interfaces) const
  {
    struct Side
    {
      typename Triangulation<dim>::active_cell_iterator cell;
      Point<dim>                                        centre;
      double                                            length;
    };
    for (const auto &interface : interfaces.interfaces())
      {
        std::array<std::vector<Side>, 2> sides;
        for (const auto &cell : triangulation.active_cell_iterators())
          for (const auto &face : cell->face_iterators())
            if (face->at_boundary())
              for (unsigned int k = 0; k < 2; ++k)
                if (face->boundary_id() ==
                    (k == 0 ? interface.slave_id : interface.master_id))
                  sides[k].push_back(
                    {cell,
                     face->center(),
                     std::pow(face->measure(), 1. / (dim - 1))});
        // Facing faces: centres closer than half the sum of their sizes
        // (length in 2D, square root of the area in 3D). Found once through
        // the contact search on the master centres, then swept until no
        // flag changes: a marked face of size h becomes h/2, and a facing
        // face larger than 0.75 h is marked too.
        double h = 0;
        for (const auto &side : sides)
          for (const Side &face : side)
            h = std::max(h, face.length);
        std::vector<BoundingBox<dim>> centres;
        for (const Side &face : sides[1])
          centres.emplace_back(std::vector<Point<dim>>{face.centre});
        const ContactSearch<dim>                           search(centres);
        std::vector<std::pair<unsigned int, unsigned int>> facing;
        for (unsigned int i = 0; i < sides[0].size(); ++i)
          {
            BoundingBox<dim> reach(std::vector<Point<dim>>{sides[0][i].centre});
            reach.extend(0.5 * (sides[0][i].length + h));
            for (const unsigned int j : search.intersecting(reach))
              if (sides[0][i].centre.distance(sides[1][j].centre) <
                  0.5 * (sides[0][i].length + sides[1][j].length))
                facing.emplace_back(i, j);
          }
        for (bool changed = true; changed;)
          {
            changed = false;
            for (const auto &[i, j] : facing)
              for (unsigned int k = 0; k < 2; ++k)
                {
                  const Side &marked = k == 0 ? sides[0][i] : sides[1][j];
                  const Side &other  = k == 0 ? sides[1][j] : sides[0][i];
                  if (marked.cell->refine_flag_set() &&
                      !other.cell->refine_flag_set() &&
                      other.length > 0.75 * marked.length)
                    {
                      other.cell->set_refine_flag();
                      changed = true;
                    }
                }
          }
      }
  }



  std::string
  Refinement::name(const Strategy strategy)
  {
    return strategy == Strategy::global     ? "uniform"
           : strategy == Strategy::adaptive ? "adaptive"
                                            : "compare";
  }


  template bool
  Refinement::refine(const Strategy,
                     Triangulation<2> &,
                     const ProblemAccess<2> &,
                     const Vector<float> *) const;
  template bool
  Refinement::refine(const Strategy,
                     Triangulation<3> &,
                     const ProblemAccess<3> &,
                     const Vector<float> *) const;
} // namespace knee_contact
