#ifndef knee_contact_problem_access_h
#define knee_contact_problem_access_h

#include <knee_contact/contact/contact.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/materials.h>
#include <knee_contact/solver/active_set.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

#include <functional>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The problem's state as its collaborators read it (the results, the
   * refinement, the summary): one read-only view instead of the ten
   * arguments each took, as ASPECT's SimulatorAccess<dim> gives its
   * plugins. ContactProblem<dim>::access() makes it; what it refers to
   * stays the problem's and outlives the call it is passed to. The
   * distributed stage of issue 38 adds its communicator and index sets
   * here, so that they reach every collaborator in one place.
   *
   * A struct of references rather than ASPECT's base class holding the
   * simulator: the collaborators live below core/ (doc/architecture.md)
   * and must not see ContactProblem.
   */
  template <int dim>
  struct ProblemAccess
  {
    const DoFHandler<dim> &dof_handler;
    /** The body (0, 1, ...) of each active cell, by active cell index. */
    const std::vector<unsigned int> &body_of_cell;
    /** y = C x and d of the unconstrained system (C's product: on several
     * ranks the iterative path holds C's rows, no rank the whole matrix). */
    const std::function<void(Vector<double> &y, const Vector<double> &x)>
                                   stiffness_product;
    const Vector<double>          &rhs;
    const Vector<double>          &solution;
    const Materials<dim>          &materials;
    const BoundaryConditions<dim> &boundary_conditions;
    const ContactInterfaces       &interfaces;
    const ContactPairs<dim>       &pairs;
    const ContactSolution         &contact;
  };
} // namespace knee_contact

#endif
