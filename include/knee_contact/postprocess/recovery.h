#ifndef knee_contact_recovery_h
#define knee_contact_recovery_h

#include <knee_contact/physics/materials.h>

#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The Zienkiewicz-Zhu estimate of the energy-norm error a(u - u_h, u -
   * u_h) by strain recovery: the strain of @p solution averaged at each
   * vertex over the cells of one material that share it (so that a bonded
   * material junction, where the strain jumps, is not smoothed over), the
   * averages interpolated by the cells' own linear shape functions, and
   * eta^2 = sum over cells of the integral of (e* - e_h) : C : (e* - e_h).
   * eta^2 estimates the error of the energy a(u, u) that the run reports
   * (Galerkin orthogonality: a(u, u) - a(u_h, u_h) = a(u - u_h, u - u_h)
   * for the linear problem; with contact up to the contact terms).
   *
   * Written here because deal.II's estimators (Kelly) give indicators with
   * an unknown constant, not an error in the quantity's units.
   */
  template <int dim>
  double
  recovered_energy_error(const DoFHandler<dim> &dof_handler,
                         const Vector<double>  &solution,
                         const Materials<dim>  &materials);
} // namespace knee_contact

#endif
