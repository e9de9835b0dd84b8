// Shared by the enumeration tests: the QP min 1/2 x^T K x - x^T f under the
// Gamma_u/Gamma_o/hanging-node constraints, written in the dofs those leave
// free (x = C0 z + g0), densely: H = C0^T K C0, b = C0^T (f - K g0).

#ifndef knee_contact_tests_free_dofs_h
#define knee_contact_tests_free_dofs_h

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/vector.h>

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

#endif
