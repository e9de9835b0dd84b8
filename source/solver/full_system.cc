// The step-41 path of the solver seam: the whole system condensed by
// AffineConstraints and factorised by UMFPACK for each active set; the
// reference the other paths are tested against (tests/unit/solver_paths.cc).
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>
#include <knee_contact/solver/springs.h>

#include <deal.II/lac/sparse_direct.h>

namespace knee_contact
{
  FullContactSystem::FullContactSystem(const SparseMatrix<double>      &matrix,
                                       const AffineConstraints<double> &base,
                                       const std::vector<ContactRow>   &pairs)
    : matrix(matrix)
    , base(base)
    , pairs(pairs)
    , system_matrix(matrix.get_sparsity_pattern())
    , system_rhs(matrix.m())
    , x(matrix.m())
  {}



  void
  FullContactSystem::set_rhs(const Vector<double> &new_rhs)
  {
    rhs = &new_rhs;
  }



  void
  FullContactSystem::solve(const std::vector<bool> &active,
                           std::vector<double>     &excess,
                           std::vector<double>     &lambda)
  {
    AffineConstraints<double> constraints;
    ActiveSetSolver::make_constraints(base, pairs, active, constraints);
    Assert(rhs != nullptr, ExcMessage("set_rhs() was not called"));
    // The springs' matrix k w w^T and load k g_w w; the condensation
    // takes the constraints' inhomogeneities through both.
    const auto terms = springs::on_dofs(springs, pairs);
    system_matrix.copy_from(matrix);
    springs::add_to_matrix(terms, system_matrix);
    system_rhs = *rhs;
    // (The springs' forces at x = 0: sum k g_w w.)
    springs::add_forces(terms, Vector<double>(matrix.m()), system_rhs);
    constraints.condense(system_matrix, system_rhs);
    SparseDirectUMFPACK direct;
    direct.initialize(system_matrix);
    direct.vmult(x, system_rhs);
    constraints.distribute(x);

    ActiveSetSolver::excess_and_multipliers(
      residual_of(matrix), *rhs, x, base, pairs, active, excess, lambda, terms);
  }



  void
  FullContactSystem::set_springs(const std::vector<Spring> &new_springs)
  {
    springs = new_springs;
  }



  double
  FullContactSystem::displacement_scale() const
  {
    return ActiveSetSolver::displacement_scale(pairs, x);
  }



  void
  FullContactSystem::solution(Vector<double> &result)
  {
    result = x;
  }
} // namespace knee_contact
