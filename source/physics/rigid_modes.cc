#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/rigid_modes.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/tensor.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/fe/fe.h>

#include <cmath>
#include <sstream>

namespace knee_contact
{
  template <int dim>
  RigidModes<dim>::RigidModes(const DoFHandler<dim>           &dof_handler,
                              const std::vector<unsigned int> &body_of_cell,
                              const std::vector<std::string>  &body_names)
    : dof_body(dof_handler.n_dofs())
    , dof_component(dof_handler.n_dofs())
    , dof_position(dof_handler.n_dofs())
    , centre(body_names.size())
    , size(body_names.size())
    , names(body_names)
  {
    // Each dof's position. The elements are linear (elements.cc): every
    // dof sits at a vertex, whose position any mapping keeps, so it is read
    // from the cells' vertices; DoFTools::map_dofs_to_support_points()
    // evaluates the mapping on every cell instead (12.7 of the set-up's
    // 41 s at 1e6 dofs, on every rank).
    const FiniteElement<dim> &fe = dof_handler.get_fe();
    AssertThrow(fe.n_dofs_per_vertex() * fe.reference_cell().n_vertices() ==
                  fe.n_dofs_per_cell(),
                ExcMessage("RigidModes: an element with dofs off the "
                           "vertices"));
    Point<dim> huge;
    for (unsigned int d = 0; d < dim; ++d)
      huge[d] = 1e300;
    std::vector<Point<dim>> lower(names.size(), huge),
      upper(names.size(), -huge);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (!cell->is_artificial())
        {
          const unsigned int body = body_of_cell[cell->active_cell_index()];
          for (const unsigned int v : cell->vertex_indices())
            {
              const Point<dim> &x = cell->vertex(v);
              for (unsigned int c = 0; c < fe.n_dofs_per_vertex(); ++c)
                {
                  const types::global_dof_index dof =
                    cell->vertex_dof_index(v, c);
                  dof_position[dof] = x;
                  dof_body[dof]     = body;
                  // FESystem numbers a vertex's dofs by component.
                  dof_component[dof] = c;
                }
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lower[body][d] = std::min(lower[body][d], x[d]);
                  upper[body][d] = std::max(upper[body][d], x[d]);
                }
            }
        }
    // A distributed mesh: every rank takes every dof's data from its
    // owner (whole vectors, as the loop's: the rows' dofs are anywhere),
    // packed as doubles for one all-gather (indices below 2^53), and the
    // bodies' boxes over the ranks.
    const auto *distributed =
      dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
        &dof_handler.get_triangulation());
    if (distributed != nullptr)
      {
        const MPI_Comm      comm = distributed->get_communicator();
        std::vector<double> mine;
        for (const auto dof : dof_handler.locally_owned_dofs())
          {
            mine.push_back(dof);
            mine.push_back(dof_body[dof]);
            mine.push_back(dof_component[dof]);
            for (unsigned int d = 0; d < dim; ++d)
              mine.push_back(dof_position[dof][d]);
          }
        const std::vector<double> all =
          parallel::gather_on_every_rank(comm, mine);
        for (std::size_t k = 0; k < all.size(); k += 3 + dim)
          {
            const auto dof     = types::global_dof_index(all[k]);
            dof_body[dof]      = all[k + 1];
            dof_component[dof] = all[k + 2];
            for (unsigned int d = 0; d < dim; ++d)
              dof_position[dof][d] = all[k + 3 + d];
          }
        for (unsigned int b = 0; b < names.size(); ++b)
          for (unsigned int d = 0; d < dim; ++d)
            {
              lower[b][d] = Utilities::MPI::min(lower[b][d], comm);
              upper[b][d] = Utilities::MPI::max(upper[b][d], comm);
            }
      }
    for (unsigned int b = 0; b < names.size(); ++b)
      {
        centre[b] = 0.5 * (lower[b] + upper[b]);
        size[b]   = std::max(0.5 * lower[b].distance(upper[b]), 1e-300);
      }
  }



  template <int dim>
  std::vector<Vector<double>>
  RigidModes<dim>::rigid_motions() const
  {
    // Each body moves by its own mode about its own centre, scaled by its
    // size, so that the vectors are of one magnitude on every body; as the
    // bodies share no dof, each is a rigid motion of every body at once.
    std::vector<Vector<double>> modes(n_modes,
                                      Vector<double>(dof_position.size()));
    for (types::global_dof_index i = 0; i < dof_position.size(); ++i)
      {
        const unsigned int   b = dof_body[i];
        const unsigned int   c = dof_component[i];
        const Tensor<1, dim> r = (dof_position[i] - centre[b]) / size[b];
        modes[c](i)            = 1;
        if constexpr (dim == 2)
          modes[2](i) = c == 0 ? -r[1] : r[0];
        else
          for (unsigned int k = 0; k < 3; ++k)
            if (k != c)
              {
                // (e_k x r)_c = epsilon_kjc r_j.
                const unsigned int j    = 3 - k - c;
                const double       sign = (k + 1) % 3 == j ? 1. : -1.;
                modes[3 + k](i)         = sign * r[j];
              }
      }
    return modes;
  }



  void
  RigidModeCheck::check(const AffineConstraints<double> &base,
                        const std::vector<ContactRow>   &rows,
                        const std::vector<bool>         &active,
                        const std::string               &context) const
  {
    const std::string motion = free_motion(base, rows, active);
    AssertThrow(motion.empty(), ExcMessage(motion + "; " + context));
  }



  template <int dim>
  std::string
  RigidModes<dim>::free_motion(const AffineConstraints<double> &base,
                               const std::vector<ContactRow>   &pairs,
                               const std::vector<bool>         &active) const
  {
    const unsigned int n_all = n_modes * names.size();
    FullMatrix<double> gram(n_all, n_all);
    Vector<double>     w(n_all);

    // Add one homogeneous constraint row sum_d v_d x_d = 0 to the Gram
    // matrix, evaluated on the modes of body b: the translations along the
    // axes, then the rotations about the axes through the body's centre
    // (2D: about z only), e_k x (x - centre), scaled by its size.
    const auto add_row =
      [&](const std::vector<std::pair<types::global_dof_index, double>> &row) {
        w           = 0;
        double norm = 0;
        for (const auto &[dof, v] : row)
          {
            const unsigned int   b = dof_body[dof];
            const unsigned int   c = dof_component[dof];
            const Tensor<1, dim> r = dof_position[dof] - centre[b];
            w(n_modes * b + c) += v;
            if constexpr (dim == 2)
              w(n_modes * b + 2) += v * (c == 0 ? -r[1] : r[0]) / size[b];
            else
              // (e_k x r)_c = epsilon_kjc r_j: nonzero for j, k, c distinct.
              for (unsigned int k = 0; k < 3; ++k)
                if (k != c)
                  {
                    const unsigned int j    = 3 - k - c;
                    const double       sign = (k + 1) % 3 == j ? 1. : -1.;
                    w(n_modes * b + 3 + k) += v * sign * r[j] / size[b];
                  }
            norm += v * v;
          }
        if (norm > 0)
          for (unsigned int i = 0; i < n_all; ++i)
            for (unsigned int j = 0; j < n_all; ++j)
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

    LAPACKFullMatrix<double> matrix(n_all);
    matrix         = gram;
    double largest = 0;
    for (unsigned int i = 0; i < n_all; ++i)
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
        for (unsigned int k = 0; k < n_modes; ++k)
          m +=
            eigenvectors(n_modes * b + k, 0) * eigenvectors(n_modes * b + k, 0);
        if (m > largest_motion + 1e-12)
          {
            largest_motion = m;
            body           = b;
          }
      }
    // u(x) = t + omega x (x - centre), omega along z in 2D.
    Tensor<1, dim> t;
    Tensor<1, 3>   omega;
    for (unsigned int d = 0; d < dim; ++d)
      t[d] = eigenvectors(n_modes * body + d, 0);
    for (unsigned int k = 0; k < n_modes - dim; ++k)
      omega[dim == 2 ? 2 : k] =
        eigenvectors(n_modes * body + dim + k, 0) / size[body];
    std::ostringstream motion;
    motion.precision(4);
    // Components at round-off of a unit direction are shown as 0.
    const auto shown = [](const double c) {
      return std::abs(c) < 1e-12 ? 0. : c;
    };
    const auto list = [&](const auto &v, const double scale) {
      std::ostringstream out;
      out.precision(4);
      for (unsigned int d = 0; d < dim; ++d)
        out << (d == 0 ? "(" : ", ") << shown(v[d] / scale);
      out << ")";
      return out.str();
    };
    if (omega.norm() * size[body] > 1e-6 * t.norm())
      {
        // The axis: the points p where u(p) is parallel to omega,
        // p = centre + omega x t / |omega|^2 (2D: the centre of rotation).
        Tensor<1, 3> t3;
        for (unsigned int d = 0; d < dim; ++d)
          t3[d] = t[d];
        const Tensor<1, 3> offset =
          cross_product_3d(omega, t3) / (omega * omega);
        Point<dim> p = centre[body];
        for (unsigned int d = 0; d < dim; ++d)
          p[d] += offset[d];
        if constexpr (dim == 2)
          motion << "rotation about (" << p[0] << ", " << p[1] << ")";
        else
          motion << "rotation about the axis through (" << p[0] << ", " << p[1]
                 << ", " << p[2] << ") along " << list(omega, omega.norm());
      }
    else
      motion << "translation along " << list(t, t.norm());
    return "body " + std::to_string(body) + " (" + names[body] +
           ") is not held: its " + motion.str() +
           " is free of every displacement, sliding and active contact "
           "constraint";
  }


  template class RigidModes<2>;
  template class RigidModes<3>;
} // namespace knee_contact
