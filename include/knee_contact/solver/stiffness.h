#ifndef knee_contact_solver_stiffness_h
#define knee_contact_solver_stiffness_h

#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <functional>

namespace knee_contact
{
  using namespace dealii;

  /**
   * b = rhs - C x with the stiffness matrix C: the one product with the
   * whole of C that the solver layer's helpers take (the condensed load,
   * the multipliers). A deal.II matrix gives it (residual_of()); the
   * iterative path on several ranks gives it from its ranks' rows in
   * Trilinos, where no rank holds C whole.
   */
  using StiffnessResidual = std::function<void(Vector<double>       &b,
                                               const Vector<double> &x,
                                               const Vector<double> &rhs)>;

  /** The residual of a deal.II matrix (kept by reference). */
  inline StiffnessResidual
  residual_of(const SparseMatrix<double> &matrix)
  {
    return [&matrix](Vector<double>       &b,
                     const Vector<double> &x,
                     const Vector<double> &rhs) { matrix.residual(b, x, rhs); };
  }
} // namespace knee_contact

#endif
