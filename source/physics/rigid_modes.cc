#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/rigid_modes.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/tensor.h>

#include <deal.II/lac/full_matrix.h>
#include <deal.II/lac/lapack_full_matrix.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace knee_contact
{
  template <int dim>
  RigidModes<dim>::RigidModes(const DoFHandler<dim>           &dof_handler,
                              const std::vector<unsigned int> &body_of_cell,
                              const std::vector<std::string>  &body_names)
    : centre(body_names.size())
    , size(body_names.size())
    , names(body_names)
  {
    // A distributed mesh: this rank knows the dofs of its cells and their
    // ghosts, and evaluates the rows on those it owns (free_motion()).
    const auto *mesh =
      dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
        &dof_handler.get_triangulation());
    distributed = mesh != nullptr;
    if (distributed)
      {
        communicator = mesh->get_communicator();
        owned        = dof_handler.locally_owned_dofs();
        DoFTools::extract_locally_relevant_dofs(dof_handler, known);
      }
    else
      {
        owned = complete_index_set(dof_handler.n_dofs());
        known = owned;
      }
    dof_body.resize(known.n_elements());
    dof_component.resize(known.n_elements());
    dof_position.resize(known.n_elements());

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
                  const std::size_t i = at(cell->vertex_dof_index(v, c));
                  dof_position[i]     = x;
                  dof_body[i]         = body;
                  // FESystem numbers a vertex's dofs by component.
                  dof_component[i] = c;
                }
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lower[body][d] = std::min(lower[body][d], x[d]);
                  upper[body][d] = std::max(upper[body][d], x[d]);
                }
            }
        }
    // The bodies' boxes over the ranks.
    if (distributed)
      for (unsigned int b = 0; b < names.size(); ++b)
        for (unsigned int d = 0; d < dim; ++d)
          {
            lower[b][d] = Utilities::MPI::min(lower[b][d], communicator);
            upper[b][d] = Utilities::MPI::max(upper[b][d], communicator);
          }
    for (unsigned int b = 0; b < names.size(); ++b)
      {
        centre[b] = 0.5 * (lower[b] + upper[b]);
        size[b]   = std::max(0.5 * lower[b].distance(upper[b]), 1e-300);
      }
  }



  template <int dim>
  std::size_t
  RigidModes<dim>::at(const types::global_dof_index dof) const
  {
    AssertThrow(known.is_element(dof),
                ExcMessage("RigidModes: dof " + std::to_string(dof) +
                           " is not one this rank knows"));
    return known.index_within_set(dof);
  }



  template <int dim>
  typename RigidModes<dim>::ModeValues
  RigidModes<dim>::modes_at(const types::global_dof_index dof) const
  {
    // The translations along the axes, then the rotations about the axes
    // through the body's centre (2D: about z only), e_k x (x - centre),
    // scaled by its size, so that the modes are of one magnitude on every
    // body; as the bodies share no dof, each is a rigid motion of every
    // body at once.
    const std::size_t    i = at(dof);
    ModeValues           values{dof_body[i], {}};
    const unsigned int   c = dof_component[i];
    const Tensor<1, dim> r =
      (dof_position[i] - centre[values.body]) / size[values.body];
    values.w[c] = 1;
    if constexpr (dim == 2)
      values.w[2] = c == 0 ? -r[1] : r[0];
    else
      // (e_k x r)_c = epsilon_kjc r_j: nonzero for j, k, c distinct.
      for (unsigned int k = 0; k < 3; ++k)
        if (k != c)
          {
            const unsigned int j    = 3 - k - c;
            const double       sign = (k + 1) % 3 == j ? 1. : -1.;
            values.w[3 + k]         = sign * r[j];
          }
    return values;
  }



  template <int dim>
  std::vector<double>
  RigidModes<dim>::rigid_motions(const IndexSet &rows) const
  {
    const std::size_t   n = rows.n_elements();
    std::vector<double> modes(n_modes * n);
    std::size_t         local = 0;
    for (const auto dof : rows)
      {
        const ModeValues values = modes_at(dof);
        for (unsigned int k = 0; k < n_modes; ++k)
          modes[k * n + local] = values.w[k];
        ++local;
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
    const unsigned int n_bodies = names.size(), n_all = n_modes * n_bodies;
    FullMatrix<double> gram(n_all, n_all);
    // Adds v times values to the part of their body (a list of a few
    // bodies, each once).
    const auto add_values = [](std::vector<ModeValues> &parts,
                               const ModeValues        &values,
                               const double             v) {
      auto part =
        std::find_if(parts.begin(), parts.end(), [&](const ModeValues &p) {
          return p.body == values.body;
        });
      if (part == parts.end())
        part = parts.insert(parts.end(), ModeValues{values.body, {}});
      for (unsigned int k = 0; k < n_modes; ++k)
        part->w[k] += v * values.w[k];
    };
    // v times the modes' values at dof.
    const auto add = [&](std::vector<ModeValues>      &parts,
                         const types::global_dof_index dof,
                         const double                  v) {
      add_values(parts, modes_at(dof), v);
    };

    // Each homogeneous constraint row sum_d v_d x_d = 0 adds w w^T / |v|^2
    // to the Gram matrix, w the row evaluated on the modes, by body. A
    // line of base on the rank that owns its dof (its entries, a vertex's
    // components or a hanging node's parents, lie on the cells around it,
    // which the rank knows); it holds one body's dofs (the bodies share
    // none), so it adds to that body's block only, and the ranks' blocks
    // are summed.
    std::vector<double>     blocks(n_bodies * n_modes * n_modes, 0.);
    std::vector<ModeValues> line_part;
    for (const auto &line : base.get_lines())
      if (owned.is_element(line.index))
        {
          line_part.clear();
          add(line_part, line.index, 1.);
          double norm = 1;
          for (const auto &[j, c] : line.entries)
            {
              add(line_part, j, -c);
              norm += c * c;
            }
          AssertThrow(line_part.size() == 1,
                      ExcMessage("RigidModes: a constraint of dof " +
                                 std::to_string(line.index) +
                                 " couples two bodies"));
          const ModeValues &w = line_part[0];
          for (unsigned int i = 0; i < n_modes; ++i)
            for (unsigned int j = 0; j < n_modes; ++j)
              blocks[(w.body * n_modes + i) * n_modes + j] +=
                w.w[i] * w.w[j] / norm;
        }

    // An active contact row: each rank evaluates it on the dofs it owns
    // (its master dofs are anywhere), by body, and every rank sums the
    // parts in the same order, so that every rank decides alike.
    struct Part
    {
      unsigned int row;
      ModeValues   values;
    };
    std::vector<Part>       parts;
    std::vector<ModeValues> row_parts;
    for (unsigned int p = 0; p < pairs.size(); ++p)
      if (active[p])
        {
          row_parts.clear();
          for (const auto &[dof, v] : pairs[p].row)
            if (owned.is_element(dof))
              add(row_parts, dof, v);
          for (const ModeValues &values : row_parts)
            parts.push_back({p, values});
        }
    if (distributed && !blocks.empty())
      {
        const std::vector<double> all =
          parallel::gather_on_every_rank(communicator, blocks);
        std::fill(blocks.begin(), blocks.end(), 0.);
        for (std::size_t k = 0; k < all.size(); ++k)
          blocks[k % blocks.size()] += all[k]; // (rank by rank)
        parts = parallel::gather_on_every_rank(communicator, parts);
        std::stable_sort(parts.begin(),
                         parts.end(),
                         [](const Part &a, const Part &b) {
                           return a.row < b.row;
                         });
      }
    for (unsigned int b = 0; b < n_bodies; ++b)
      for (unsigned int i = 0; i < n_modes; ++i)
        for (unsigned int j = 0; j < n_modes; ++j)
          gram(n_modes * b + i, n_modes * b + j) =
            blocks[(b * n_modes + i) * n_modes + j];
    for (std::size_t first = 0; first < parts.size();)
      {
        // The row's parts from every rank, summed by body.
        const unsigned int p = parts[first].row;
        row_parts.clear();
        for (; first < parts.size() && parts[first].row == p; ++first)
          add_values(row_parts, parts[first].values, 1.);
        double norm = 0;
        for (const auto &[dof, v] : pairs[p].row)
          norm += v * v;
        if (norm > 0)
          for (const ModeValues &a : row_parts)
            for (const ModeValues &c : row_parts)
              for (unsigned int i = 0; i < n_modes; ++i)
                for (unsigned int j = 0; j < n_modes; ++j)
                  gram(n_modes * a.body + i, n_modes * c.body + j) +=
                    a.w[i] * c.w[j] / norm;
      }

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
    // An eigenvector's sign is arbitrary (the round-off of the dofs'
    // order decides it): the mode is shown with its largest coefficient
    // positive (of those equal to 1e-12, the first), so that one scene gives
    // one message.
    double sign = 1, largest_coefficient = 0;
    for (unsigned int k = 0; k < n_modes; ++k)
      {
        const double v = eigenvectors(n_modes * body + k, 0);
        if (std::abs(v) > largest_coefficient + 1e-12)
          {
            largest_coefficient = std::abs(v);
            sign                = v < 0 ? -1. : 1.;
          }
      }
    // u(x) = t + omega x (x - centre), omega along z in 2D.
    Tensor<1, dim> t;
    Tensor<1, 3>   omega;
    for (unsigned int d = 0; d < dim; ++d)
      t[d] = sign * eigenvectors(n_modes * body + d, 0);
    for (unsigned int k = 0; k < n_modes - dim; ++k)
      omega[dim == 2 ? 2 : k] =
        sign * eigenvectors(n_modes * body + dim + k, 0) / size[body];
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
