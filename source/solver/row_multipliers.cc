#include <knee_contact/solver/row_multipliers.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>

#include <map>

namespace knee_contact
{
  RowMultipliers::RowMultipliers(
    const AffineConstraints<double>                 &base,
    const std::vector<ContactRow>                   &rows,
    const std::vector<bool>                         &active,
    const std::vector<ContactSystem::BoundCoupling> &couplings)
    : equation_of_row(rows.size(), numbers::invalid_unsigned_int)
  {
    // One equation per active row, at the dof it eliminates.
    std::map<types::global_dof_index, unsigned int> equation_of_dof;
    for (unsigned int p = 0; p < rows.size(); ++p)
      if (active[p])
        {
          AssertThrow(rows[p].eliminated != numbers::invalid_dof_index,
                      ExcInternalError());
          equation_of_row[p]                  = n_equations;
          equation_of_dof[rows[p].eliminated] = n_equations++;
        }
    // E: the eliminated dofs themselves and, through C0^T, each
    // Gamma_u/Gamma_o line's dof onto its eliminated masters.
    for (const auto &[dof, q] : equation_of_dof)
      e_entries.push_back({dof, q, 1.});
    for (const auto &line : base.get_lines())
      for (const auto &[j, c] : line.entries)
        if (const auto it = equation_of_dof.find(j);
            it != equation_of_dof.end())
          e_entries.push_back({line.index, it->second, c});
    // E's entries by dof (E of B's columns below).
    std::multimap<types::global_dof_index, std::pair<unsigned int, double>>
      e_of_dof;
    for (const Entry &entry : e_entries)
      e_of_dof.emplace(entry.dof,
                       std::make_pair(entry.equation, entry.coefficient));

    // B's columns on the full tangential rows.
    for (const auto &coupling : couplings)
      {
        AssertThrow(coupling.normal_row < rows.size() &&
                      active[coupling.normal_row],
                    ExcInternalError());
        const unsigned int q = equation_of_row[coupling.normal_row];
        for (const auto &[r, c] : coupling.rows)
          for (const auto &[dof, a] : rows[r].row)
            b_entries.push_back({dof, q, c * a});
      }

    // M + E B: M's column q is E of row q's reduced coefficients (which
    // are C0^T of its full ones) at the eliminated dofs.
    if (n_equations == 0)
      return;
    DynamicSparsityPattern dsp(n_equations, n_equations);
    std::vector<std::pair<std::pair<unsigned int, unsigned int>, double>>
      values;
    for (unsigned int p = 0; p < rows.size(); ++p)
      if (active[p])
        for (const auto &[dof, a] : rows[p].reduced_row)
          if (const auto it = equation_of_dof.find(dof);
              it != equation_of_dof.end())
            values.push_back({{it->second, equation_of_row[p]}, a});
    for (const Entry &entry : b_entries)
      {
        const auto [first, last] = e_of_dof.equal_range(entry.dof);
        for (auto it = first; it != last; ++it)
          values.push_back({{it->second.first, entry.equation},
                            it->second.second * entry.coefficient});
      }
    for (const auto &[at, value] : values)
      dsp.add(at.first, at.second);
    sparsity.copy_from(dsp);
    matrix.reinit(sparsity);
    for (const auto &[at, value] : values)
      matrix.add(at.first, at.second, value);
    factor.initialize(matrix);
  }



  std::vector<double>
  RowMultipliers::operator()(const Vector<double> &residual) const
  {
    std::vector<double> lambda(equation_of_row.size(), 0.);
    if (n_equations == 0)
      return lambda;
    Vector<double> t = gather([](auto) { return true; },
                              [&](const auto i) { return residual(i); });
    solve(t);
    for (unsigned int p = 0; p < equation_of_row.size(); ++p)
      if (equation_of_row[p] != numbers::invalid_unsigned_int)
        lambda[p] = t(equation_of_row[p]);
    return lambda;
  }



  void
  RowMultipliers::project(Vector<double> &r) const
  {
    if (!coupled())
      return;
    Vector<double> z =
      gather([](auto) { return true; }, [&](const auto i) { return r(i); });
    solve(z);
    scatter(z, [&](const auto i, const double v) { r(i) += v; });
  }



  Vector<double>
  RowMultipliers::gather(
    const std::function<bool(types::global_dof_index)>   &has,
    const std::function<double(types::global_dof_index)> &value) const
  {
    Vector<double> t(n_equations);
    for (const Entry &entry : e_entries)
      if (has(entry.dof))
        t(entry.equation) += entry.coefficient * value(entry.dof);
    return t;
  }



  void
  RowMultipliers::solve(Vector<double> &t) const
  {
    if (n_equations > 0)
      factor.solve(t);
  }



  void
  RowMultipliers::scatter(
    const Vector<double>                                       &z,
    const std::function<void(types::global_dof_index, double)> &add) const
  {
    for (const Entry &entry : b_entries)
      add(entry.dof, -entry.coefficient * z(entry.equation));
  }
} // namespace knee_contact
