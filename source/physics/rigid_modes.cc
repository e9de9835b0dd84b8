#include <knee_contact/physics/elements.h>
#include <knee_contact/physics/rigid_modes.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/mapping_q1.h>

#include <cmath>
#include <sstream>

namespace knee_contact
{
  RigidModes::RigidModes(const DoFHandler<2>             &dof_handler,
                         const std::vector<unsigned int> &body_of_cell,
                         const std::vector<std::string>  &body_names)
    : dof_body(dof_handler.n_dofs())
    , dof_component(dof_handler.n_dofs())
    , dof_position(dof_handler.n_dofs())
    , centre(body_names.size())
    , size(body_names.size())
    , names(body_names)
  {
    DoFTools::map_dofs_to_support_points(elements::mapping(dof_handler),
                                         dof_handler,
                                         dof_position);
    std::vector<types::global_dof_index> dofs(
      dof_handler.get_fe().n_dofs_per_cell());
    std::vector<Point<2>> lower(names.size(), Point<2>(1e300, 1e300)),
      upper(names.size(), Point<2>(-1e300, -1e300));
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        const unsigned int body = body_of_cell[cell->active_cell_index()];
        cell->get_dof_indices(dofs);
        for (unsigned int i = 0; i < dofs.size(); ++i)
          {
            dof_body[dofs[i]] = body;
            dof_component[dofs[i]] =
              dof_handler.get_fe().system_to_component_index(i).first;
            for (unsigned int d = 0; d < 2; ++d)
              {
                lower[body][d] =
                  std::min(lower[body][d], dof_position[dofs[i]][d]);
                upper[body][d] =
                  std::max(upper[body][d], dof_position[dofs[i]][d]);
              }
          }
      }
    for (unsigned int b = 0; b < names.size(); ++b)
      {
        centre[b] = 0.5 * (lower[b] + upper[b]);
        size[b]   = std::max(0.5 * lower[b].distance(upper[b]), 1e-300);
      }
  }



  void
  RigidModes::check(const AffineConstraints<double> &base,
                    const std::vector<ContactPair>  &pairs,
                    const std::vector<bool>         &active,
                    const std::string               &context) const
  {
    const std::string motion = free_motion(base, pairs, active);
    AssertThrow(motion.empty(), ExcMessage(motion + "; " + context));
  }



  std::string
  RigidModes::free_motion(const AffineConstraints<double> &base,
                          const std::vector<ContactPair>  &pairs,
                          const std::vector<bool>         &active) const
  {
    const unsigned int n_modes = 3 * names.size();
    FullMatrix<double> gram(n_modes, n_modes);
    Vector<double>     w(n_modes);

    // Add one homogeneous constraint row sum_d v_d x_d = 0 to the Gram
    // matrix, evaluated on mode (b, k): translation x, translation y, and
    // rotation about the body's centre scaled by its size.
    const auto add_row =
      [&](const std::vector<std::pair<types::global_dof_index, double>> &row) {
        w           = 0;
        double norm = 0;
        for (const auto &[dof, v] : row)
          {
            const unsigned int b = dof_body[dof];
            const unsigned int c = dof_component[dof];
            const Point<2>    &x = dof_position[dof];
            w(3 * b + c) += v;
            w(3 * b + 2) +=
              v * (c == 0 ? -(x[1] - centre[b][1]) : (x[0] - centre[b][0])) /
              size[b];
            norm += v * v;
          }
        if (norm > 0)
          for (unsigned int i = 0; i < n_modes; ++i)
            for (unsigned int j = 0; j < n_modes; ++j)
              gram(i, j) += w(i) * w(j) / norm;
      };

    std::vector<std::pair<types::global_dof_index, double>> row;
    for (const auto &line : base.get_lines())
      {
        row.assign(1, {line.index, 1.});
        for (const auto &[j, c] : line.entries)
          row.emplace_back(j, -c);
        add_row(row);
      }
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (active[p])
        add_row(pairs[p].row);

    LAPACKFullMatrix<double> matrix(n_modes);
    matrix         = gram;
    double largest = 0;
    for (unsigned int i = 0; i < n_modes; ++i)
      largest = std::max(largest, gram(i, i));
    Vector<double>     eigenvalues;
    FullMatrix<double> eigenvectors;
    const double       threshold = 1e-10 * std::max(largest, 1.);
    matrix.compute_eigenvalues_symmetric(
      -1., threshold, 1e-14, eigenvalues, eigenvectors);
    if (eigenvalues.size() == 0)
      return "";

    // Name the body that moves most in the first free mode, and the motion.
    unsigned int body           = 0;
    double       largest_motion = -1;
    for (unsigned int b = 0; b < names.size(); ++b)
      {
        double m = 0;
        for (unsigned int k = 0; k < 3; ++k)
          m += eigenvectors(3 * b + k, 0) * eigenvectors(3 * b + k, 0);
        if (m > largest_motion + 1e-12)
          {
            largest_motion = m;
            body           = b;
          }
      }
    const double       tx    = eigenvectors(3 * body, 0);
    const double       ty    = eigenvectors(3 * body + 1, 0);
    const double       omega = eigenvectors(3 * body + 2, 0) / size[body];
    std::ostringstream motion;
    motion.precision(4);
    const double t = std::sqrt(tx * tx + ty * ty);
    if (std::abs(omega) * size[body] > 1e-6 * t)
      // A rotation omega about p moves x by omega (-(y - p_y), x - p_x):
      // the same as rotation about the centre plus a translation.
      motion << "rotation about (" << centre[body][0] - ty / omega << ", "
             << centre[body][1] + tx / omega << ")";
    else
      {
        // Components at round-off of the unit direction are shown as 0.
        const auto shown = [](const double c) {
          return std::abs(c) < 1e-12 ? 0. : c;
        };
        motion << "translation along (" << shown(tx / t) << ", "
               << shown(ty / t) << ")";
      }
    return "body " + std::to_string(body) + " (" + names[body] +
           ") is not held: its " + motion.str() +
           " is free of every displacement, sliding and active contact "
           "constraint";
  }
} // namespace knee_contact
