// Shared by the enumeration tests: the QP min 1/2 x^T K x - x^T f under the
// Gamma_u/Gamma_o/hanging-node constraints, written in the dofs those leave
// free (x = C0 z + g0), densely: H = C0^T K C0, b = C0^T (f - K g0).

#ifndef knee_contact_tests_free_dofs_h
#define knee_contact_tests_free_dofs_h

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

#include <iostream>
#include <vector>

struct FreeDofs
{
  unsigned int               n_free = 0;
  dealii::FullMatrix<double> C0, H;
  dealii::Vector<double>     g0, b;

  FreeDofs(const dealii::SparseMatrix<double>      &K,
           const dealii::Vector<double>            &f,
           const dealii::AffineConstraints<double> &base)
  {
    using namespace dealii;
    const unsigned int        n = K.m();
    std::vector<unsigned int> free_index(n, numbers::invalid_unsigned_int);
    for (unsigned int i = 0; i < n; ++i)
      if (!base.is_constrained(i))
        free_index[i] = n_free++;
    C0.reinit(n, n_free);
    g0.reinit(n);
    for (unsigned int i = 0; i < n; ++i)
      if (free_index[i] != numbers::invalid_unsigned_int)
        C0(i, free_index[i]) = 1;
      else
        {
          g0(i) = base.get_inhomogeneity(i);
          for (const auto &[j, c] : *base.get_constraint_entries(i))
            C0(i, free_index[j]) = c;
        }
    FullMatrix<double> Kfull(n, n), KC(n, n_free);
    Kfull.copy_from(K);
    Kfull.mmult(KC, C0);
    H.reinit(n_free, n_free);
    C0.Tmmult(H, KC);
    Vector<double> Kg(n), fmKg(f);
    Kfull.vmult(Kg, g0);
    fmKg -= Kg;
    b.reinit(n_free);
    C0.Tvmult(b, fmKg);
  }
};

/**
 * The rows @p rows (a_r x <= g_r) in the free dofs: A z <= c with
 * A = a_r C0 and c = g_r - a_r g0.
 */
template <typename Row>
void
rows_in_free_dofs(const std::vector<const Row *> &rows,
                  const FreeDofs                 &reduced,
                  dealii::FullMatrix<double>     &A,
                  dealii::Vector<double>         &c)
{
  A.reinit(rows.size(), reduced.n_free);
  c.reinit(rows.size());
  for (unsigned int r = 0; r < rows.size(); ++r)
    {
      c(r) = rows[r]->gap;
      for (const auto &[dof, a] : rows[r]->row)
        {
          c(r) -= a * reduced.g0(dof);
          for (unsigned int j = 0; j < reduced.n_free; ++j)
            A(r, j) += a * reduced.C0(dof, j);
        }
    }
}

/**
 * The friction enumeration tests' verdict: the loop's statuses are the
 * enumerated state's, x and the multipliers agree to 1e-10 relative, the
 * run succeeded and every status (bits of @p seen: open, stick, slip)
 * occurs; printed, and returned.
 */
inline bool
friction_verdict(const bool         same_states,
                 const double       x_error,
                 const double       lambda_error,
                 const int          status,
                 const unsigned int seen)
{
  const bool pass = same_states && x_error <= 1e-10 && lambda_error <= 1e-10 &&
                    status == 0 && seen == 7;
  std::cout << "check statuses equal, relative differences of x and of "
               "lambda_n, lambda_t to the enumerated solution <= 1e-10, "
               "every state present: "
            << (pass ? "PASS" : "FAIL") << std::endl;
  if (!pass)
    std::cout << "  x " << x_error << ", lambda " << lambda_error
              << ", states present (bits open, stick, slip) " << seen
              << std::endl;
  return pass;
}

#endif
