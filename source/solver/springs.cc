#include <knee_contact/solver/sparse_cholesky.h>
#include <knee_contact/solver/springs.h>

#include <deal.II/base/exceptions.h>

#include <map>
#include <string>

namespace knee_contact
{
  namespace springs
  {
    std::vector<SpringTerm>
    on_dofs(const std::vector<ContactSystem::Spring> &springs,
            const std::vector<ContactRow>            &pairs)
    {
      std::vector<SpringTerm> terms;
      terms.reserve(springs.size());
      for (const auto &spring : springs)
        {
          SpringTerm term;
          term.stiffness = spring.stiffness;
          std::map<types::global_dof_index, double> w;
          for (const auto &[r, c] : spring.rows)
            {
              for (const auto &[i, a] : pairs[r].reduced_row)
                w[i] += c * a;
              term.g_w += c * pairs[r].reduced_gap;
            }
          term.w.assign(w.begin(), w.end());
          terms.push_back(std::move(term));
        }
      return terms;
    }



    bool
    same_matrix(const std::vector<SpringTerm> &a,
                const std::vector<SpringTerm> &b)
    {
      if (a.size() != b.size())
        return false;
      for (std::size_t s = 0; s < a.size(); ++s)
        if (a[s].stiffness != b[s].stiffness || a[s].w != b[s].w)
          return false;
      return true;
    }



    void
    add_to_matrix(const std::vector<SpringTerm> &springs,
                  SparseMatrix<double>          &matrix)
    {
      const SparsityPattern &pattern = matrix.get_sparsity_pattern();
      for (const auto &spring : springs)
        for (const auto &[i, a] : spring.w)
          for (const auto &[j, b] : spring.w)
            {
              // SparseMatrix::add() drops an entry outside the pattern
              // without a word in a release build.
              AssertThrow(pattern.exists(i, j),
                          ExcMessage("internal error: a friction spring "
                                     "couples dofs " +
                                     std::to_string(i) + " and " +
                                     std::to_string(j) +
                                     ", which the sparsity pattern does not"));
              matrix.add(i, j, spring.stiffness * a * b);
            }
    }



    void
    add_forces(const std::vector<SpringTerm> &springs,
               const Vector<double>          &x,
               Vector<double>                &v)
    {
      for (const auto &spring : springs)
        {
          const double force = spring.stiffness * (spring.g_w - spring.dot(x));
          for (const auto &[i, a] : spring.w)
            v(i) += force * a;
        }
    }



    Vector<double>
    condensed_load(const std::vector<SpringTerm>   &springs,
                   const SparseMatrix<double>      &matrix,
                   const Vector<double>            &rhs,
                   const AffineConstraints<double> &constraints)
    {
      if (springs.empty())
        return sparse_cholesky::condense(matrix, rhs, constraints);
      Vector<double> g(rhs.size()), load = rhs;
      constraints.distribute(g);
      add_forces(springs, g, load);
      return sparse_cholesky::condense(matrix, load, constraints);
    }



    void
    vmult_add(const std::vector<SpringTerm> &springs,
              const Vector<double>          &x,
              Vector<double>                &v)
    {
      for (const auto &spring : springs)
        {
          const double force = spring.stiffness * spring.dot(x);
          for (const auto &[i, a] : spring.w)
            v(i) += force * a;
        }
    }
  } // namespace springs
} // namespace knee_contact
