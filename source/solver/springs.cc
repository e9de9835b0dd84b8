#include <knee_contact/solver/sparse_cholesky.h>
#include <knee_contact/solver/springs.h>

#include <deal.II/base/exceptions.h>

#include <algorithm>
#include <cmath>
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
    condensed_load(const std::vector<SpringTerm>               &springs,
                   const StiffnessResidual                     &residual,
                   const Vector<double>                        &rhs,
                   const AffineConstraints<double>             &constraints,
                   const std::function<void(Vector<double> &)> &before_folding)
    {
      if (springs.empty() && !before_folding)
        return sparse_cholesky::condense(residual, rhs, constraints);
      Vector<double> g(rhs.size()), load = rhs;
      constraints.distribute(g);
      add_forces(springs, g, load);
      if (!before_folding)
        return sparse_cholesky::condense(residual, load, constraints);
      // (distribute() gave g on the constrained dofs: the masters are
      // free, zero.)
      Vector<double> b(rhs.size());
      residual(b, g, load);
      before_folding(b);
      sparse_cholesky::condense_homogeneous(constraints, b);
      return b;
    }


    Ties
    tie_stiff(const std::vector<ContactSystem::Spring>             &springs,
              const std::vector<SpringTerm>                        &terms,
              const std::vector<ContactRow>                        &rows,
              const std::vector<bool>                              &active,
              const std::function<double(types::global_dof_index)> &diagonal,
              const double                                          ratio)
    {
      AssertThrow(springs.size() == terms.size(), ExcInternalError());
      Ties ties;
      // The dofs the active rows (and the ties made so far) eliminate, by
      // their row in the extended list.
      std::map<types::global_dof_index, std::size_t> eliminated_by;
      for (std::size_t p = 0; p < rows.size(); ++p)
        if (active[p] && rows[p].eliminated != numbers::invalid_dof_index)
          eliminated_by[rows[p].eliminated] = p;
      const auto row_of = [&](const std::size_t index) -> const ContactRow & {
        return index < rows.size() ? rows[index]
                                   : ties.for_constraints[index - rows.size()];
      };

      for (std::size_t s = 0; s < terms.size(); ++s)
        {
          const SpringTerm &term = terms[s];
          double            w2 = 0, wcw = 0;
          for (const auto &[i, a] : term.w)
            {
              w2 += a * a;
              wcw += a * a * diagonal(i);
            }
          if (!(wcw > 0 && term.stiffness * w2 * w2 >= ratio * wcw))
            {
              ties.kept.push_back(term);
              continue;
            }
          // w with the active rows on its dofs subtracted (Gaussian
          // elimination of their eliminated dofs, a row's other dofs joining
          // w's: of the 3D knee's springs one in six shares dofs with a
          // neighbouring pair's normal row), at most a few rows.
          std::map<types::global_dof_index, double> reduced(term.w.begin(),
                                                            term.w.end());
          double                                    scale = 0;
          for (const auto &[i, a] : term.w)
            scale = std::max(scale, std::abs(a));
          double       gap          = term.g_w;
          unsigned int n_subtracted = 0;
          const auto   next_held    = [&]() {
            for (const auto &[i, a] : reduced)
              if (std::abs(a) > 1e-12 * scale && eliminated_by.count(i) != 0)
                return i;
            return numbers::invalid_dof_index;
          };
          for (auto i = next_held();
               i != numbers::invalid_dof_index && n_subtracted <= 8;
               i = next_held(), ++n_subtracted)
            {
              const ContactRow &row = row_of(eliminated_by[i]);
              double            a_i = 0;
              for (const auto &[j, b] : row.reduced_row)
                if (j == i)
                  a_i = b;
              const double alpha = reduced[i] / a_i;
              for (const auto &[j, b] : row.reduced_row)
                reduced[j] -= alpha * b;
              gap -= alpha * row.reduced_gap;
              reduced[i] = 0;
            }
          const bool inside = next_held() == numbers::invalid_dof_index;
          // The dof to eliminate: w's largest free one, of a size with w's.
          double                  largest = 0, largest_free = 0;
          types::global_dof_index chosen = numbers::invalid_dof_index;
          for (const auto &[i, a] : reduced)
            {
              largest = std::max(largest, std::abs(a));
              if (eliminated_by.count(i) == 0 && std::abs(a) > largest_free)
                {
                  largest_free = std::abs(a);
                  chosen       = i;
                }
            }
          if (!inside || chosen == numbers::invalid_dof_index ||
              largest_free < 0.1 * largest)
            {
              ties.kept.push_back(term);
              continue;
            }

          ContactRow        tie;
          const ContactRow &first = rows[springs[s].rows.front().first];
          tie.interface           = first.interface;
          tie.length              = first.length;
          tie.eliminated          = chosen;
          std::map<types::global_dof_index, double> row;
          for (const auto &[r, c] : springs[s].rows)
            {
              for (const auto &[i, a] : rows[r].row)
                row[i] += c * a;
              tie.gap += c * rows[r].gap;
            }
          tie.row.assign(row.begin(), row.end());
          ContactRow for_multipliers = tie;
          for (const auto &[i, a] : reduced)
            if (a != 0)
              tie.reduced_row.emplace_back(i, a);
          tie.reduced_gap             = gap;
          for_multipliers.reduced_row = term.w;
          for_multipliers.reduced_gap = term.g_w;
          eliminated_by[chosen]       = rows.size() + ties.rows.size();
          ties.for_constraints.push_back(std::move(tie));
          ties.for_multipliers.push_back(std::move(for_multipliers));
          ties.stiffness.push_back(term.stiffness);
          ties.rows.push_back(springs[s].rows);
        }
      return ties;
    }



    void
    untie(const Ties          &ties,
          const unsigned int   n_rows,
          std::vector<double> &excess,
          std::vector<double> &lambda)
    {
      for (std::size_t t = 0; t < ties.rows.size(); ++t)
        {
          double c2 = 0;
          for (const auto &[r, c] : ties.rows[t])
            c2 += c * c;
          const double stretch = lambda[n_rows + t] / ties.stiffness[t];
          for (const auto &[r, c] : ties.rows[t])
            excess[r] += stretch * c / c2;
        }
      excess.resize(n_rows);
      lambda.resize(n_rows);
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
