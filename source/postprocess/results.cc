#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/results.h>

#include <deal.II/base/mpi.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/dofs/dof_tools.h>
#include <deal.II/fe/fe_values.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace knee_contact
{
  template <int dim>
  Results<dim>
  compute_results(const ProblemAccess<dim> &state)
  {
    const auto &[dof_handler,
                 body_of_cell,
                 stiffness_product,
                 rhs,
                 solution,
                 materials,
                 boundary_conditions,
                 interfaces,
                 pairs,
                 contact] = state;
    Results<dim> results;
    results.n_dofs = dof_handler.n_dofs();
    // On a distributed mesh (DistributedMesh) each rank visits the cells
    // it owns (the sums below over the dofs it owns, a vertex's dofs all
    // one rank's) and the ranks sum and take the extremes; the vectors
    // (C x, d, x) and the contact rows are every rank's, whole. A whole
    // mesh's cells and dofs are all owned: no reduction.
    const auto *distributed =
      dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
        &dof_handler.get_triangulation());
    const IndexSet owned = dof_handler.locally_owned_dofs();
    results.n_cells  = dof_handler.get_triangulation().n_global_active_cells();
    results.elements = elements::name(dof_handler.get_fe().reference_cell());
    results.n_bodies =
      body_of_cell.empty()
        ? 0
        : *std::max_element(body_of_cell.begin(), body_of_cell.end()) + 1;
    if (distributed != nullptr)
      results.n_bodies =
        Utilities::MPI::max(results.n_bodies, distributed->get_communicator());

    // The force each dof's vertex receives from its supports: the
    // residual d - C x of the unconstrained system minus the contact forces
    // A^T lambda, with the sign of a reaction (C x = d + R - A^T lambda).
    Vector<double> product(dof_handler.n_dofs());
    stiffness_product(product, solution);
    Vector<double> support_force = product;
    support_force -= rhs;
    for (unsigned int p = 0; p < pairs.size(); ++p)
      for (const auto &[dof, a] : pairs.rows[p].row)
        support_force(dof) += a * contact.lambda[p];
    // With friction the tangential forces T^T lambda_t too.
    for (unsigned int j = 0; j + 1 < dim; ++j)
      for (unsigned int p = 0; p < pairs.tangential[j].size(); ++p)
        for (const auto &[dof, a] : pairs.tangential[j][p].row)
          support_force(dof) += a * contact.lambda_t[p][j];
    // A hanging node's force belongs to the vertices it hangs from:
    // apply the transpose of its constraint.
    {
      AffineConstraints<double> hanging;
      DoFTools::make_hanging_node_constraints(dof_handler, hanging);
      hanging.close();
      for (const auto &line : hanging.get_lines())
        {
          for (const auto &[j, c] : line.entries)
            support_force(j) += c * support_force(line.index);
          support_force(line.index) = 0;
        }
    }
    // a(u,u) = x^T C x, summed in a fixed order: SparseMatrix's own
    // matrix_norm_square() is a threaded reduction whose last bit varies
    // from run to run.
    results.energy = 0;
    for (unsigned int i = 0; i < solution.size(); ++i)
      results.energy += solution(i) * product(i);
    results.max_displacement = solution.linfty_norm();

    // Applied load and reactions by vertex, each vertex once.
    std::vector<bool> counted(dof_handler.n_dofs(), false);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        for (const unsigned int v : cell->vertex_indices())
          for (unsigned int d = 0; d < dim; ++d)
            {
              const auto dof = cell->vertex_dof_index(v, d);
              if (!counted[dof] && owned.is_element(dof))
                results.applied_load[d] += rhs(dof);
              counted[dof] = true;
            }
    // Each component goes to the condition that holds it: a displacement
    // condition for its prescribed components first, then sliding.
    std::fill(counted.begin(), counted.end(), false);
    for (const bool sliding : {false, true})
      for (const auto &condition : boundary_conditions.conditions())
        if (condition.type ==
            (sliding ? BoundaryType::sliding : BoundaryType::displacement))
          for (const auto &cell : dof_handler.active_cell_iterators())
            if (!cell->is_artificial())
              for (const auto &face : cell->face_iterators())
                if (face->at_boundary() &&
                    condition.ids.count(face->boundary_id()))
                  for (const unsigned int v : face->vertex_indices())
                    for (unsigned int d = 0; d < dim; ++d)
                      {
                        const auto dof = face->vertex_dof_index(v, d);
                        if (!counted[dof] && owned.is_element(dof) &&
                            (sliding || condition.mask[d]))
                          {
                            results.reactions[face->boundary_id()][d] +=
                              support_force(dof);
                            counted[dof] = true;
                          }
                      }
    if (distributed != nullptr)
      {
        // The load and each boundary id's reaction summed over the ranks
        // (an id's faces can lie on some ranks only: every id of a
        // condition is summed, those no rank has left out).
        const MPI_Comm comm  = distributed->get_communicator();
        results.applied_load = Utilities::MPI::sum(results.applied_load, comm);
        std::map<types::boundary_id, Tensor<1, dim>> reactions;
        for (const auto &condition : boundary_conditions.conditions())
          for (const types::boundary_id id : condition.ids)
            {
              const auto found = results.reactions.find(id);
              const bool here  = found != results.reactions.end();
              const auto sum =
                Utilities::MPI::sum(here ? found->second : Tensor<1, dim>(),
                                    comm);
              if (Utilities::MPI::max(int(here), comm) == 1)
                reactions[id] = sum;
            }
        results.reactions = std::move(reactions);
      }
    // The force scale: the load, the reactions, or for a scene driven by
    // prescribed displacements the force E max|u| that straining a body of
    // unit size by max|u| takes.
    Tensor<1, dim> balance = results.applied_load;
    double         scale =
      std::max(results.applied_load.norm(),
               materials.max_youngs_modulus() * results.max_displacement);
    for (const auto &reaction : results.reactions)
      {
        balance += reaction.second;
        scale = std::max(scale, reaction.second.norm());
      }
    results.equilibrium_residual = scale > 0 ? balance.norm() / scale : 0;

    // tau_yy and von Mises at the vertices of every cell, as the pictures
    // show them. (Q1: the trapezoidal rule's points are the vertices in
    // deal.II's order; P1: the simplex's vertices.)
    const ReferenceCell kind = dof_handler.get_fe().reference_cell();
    FEValues<dim>       fe_values(elements::mapping(dof_handler),
                            dof_handler.get_fe(),
                            kind.template get_nodal_type_quadrature<dim>(),
                            update_gradients);
    const unsigned int  n_vertices = kind.n_vertices();
    std::vector<SymmetricTensor<2, dim>> strains(n_vertices);
    const FEValuesExtractors::Vector     displacement(0);
    results.n_cell_vertices = n_vertices;
    // (By this rank's active cell index: a distributed mesh's cells here.)
    const std::size_t n_here = dof_handler.get_triangulation().n_active_cells();
    results.vertex_stress_yy.resize(n_here * n_vertices);
    results.vertex_von_mises.resize(n_here * n_vertices);
    for (const auto &cell : dof_handler.active_cell_iterators())
      if (cell->is_locally_owned())
        {
          fe_values.reinit(cell);
          fe_values[displacement].get_function_symmetric_gradients(solution,
                                                                   strains);
          const Material<dim> &material = materials[cell->material_id()];
          auto                 range    = results.stress_yy_range.emplace(
            cell->material_id(),
            std::make_pair(std::numeric_limits<double>::max(),
                           -std::numeric_limits<double>::max()));
          double &von_mises_max = results.von_mises_max[cell->material_id()];
          for (unsigned int v = 0; v < n_vertices; ++v)
            {
              const SymmetricTensor<2, dim> stress =
                material.stress(strains[v]);
              const double      syy = stress[1][1];
              const std::size_t entry =
                results.vertex_entry(cell->active_cell_index(), v);
              results.vertex_stress_yy[entry] = syy;
              const double von_mises          = material.von_mises(stress);
              results.vertex_von_mises[entry] = von_mises;
              von_mises_max = std::max(von_mises_max, von_mises);
              range.first->second.first =
                std::min(range.first->second.first, syy);
              range.first->second.second =
                std::max(range.first->second.second, syy);
            }
        }

    if (distributed != nullptr)
      {
        // Each material's extremes over the ranks (a material can lie on
        // some ranks only).
        const MPI_Comm               comm = distributed->get_communicator();
        const double                 huge = std::numeric_limits<double>::max();
        std::set<types::material_id> ids;
        for (const auto &[id, range] : results.stress_yy_range)
          ids.insert(id);
        const std::vector<unsigned int> all = parallel::gather_on_every_rank(
          comm, std::vector<unsigned int>(ids.begin(), ids.end()));
        ids.insert(all.begin(), all.end());
        for (const types::material_id id : ids)
          {
            const auto found = results.stress_yy_range.find(id);
            const bool here  = found != results.stress_yy_range.end();
            const std::pair<double, double> range =
              here ? found->second : std::make_pair(huge, -huge);
            results.stress_yy_range[id] = {
              Utilities::MPI::min(range.first, comm),
              Utilities::MPI::max(range.second, comm)};
            results.von_mises_max[id] =
              Utilities::MPI::max(here ? results.von_mises_max[id] : 0., comm);
          }
      }
    results.interfaces.resize(interfaces.interfaces().size());
    for (unsigned int i = 0; i < results.interfaces.size(); ++i)
      {
        results.interfaces[i].name     = interfaces.interfaces()[i].name;
        results.interfaces[i].pairing  = interfaces.interfaces()[i].pairing;
        results.interfaces[i].friction = !contact.lambda_t.empty();
      }
    results.pressure.resize(pairs.size());
    for (unsigned int p = 0; p < pairs.size(); ++p)
      {
        InterfaceResult<dim> &r = results.interfaces[pairs.rows[p].interface];
        results.pressure[p]     = contact.lambda[p] / pairs.rows[p].length;
        ++r.n_pairs;
        r.force += contact.lambda[p];
        r.force_on_slave -= contact.lambda[p] * pairs.points[p].normal;
        if (!contact.lambda_t.empty())
          {
            // Along the tangents of the tangential rows.
            for (unsigned int j = 0; j + 1 < dim; ++j)
              r.tangential_force_on_slave -=
                contact.lambda_t[p][j] * pairs.points[p].tangents[j];
            if (contact.status[p] == ContactSolution::Status::stick)
              {
                ++r.n_stick;
                r.stick_length += pairs.rows[p].length;
              }
            if (contact.status[p] == ContactSolution::Status::slip)
              {
                ++r.n_slip;
                r.slip_length += pairs.rows[p].length;
                r.max_slip = std::max(r.max_slip, magnitude(contact.slip[p]));
              }
            if (p < contact.accumulated_slip.size())
              r.max_accumulated_slip =
                std::max(r.max_accumulated_slip, contact.accumulated_slip[p]);
          }
        if (contact.active[p])
          {
            ++r.n_active;
            r.contact_length += pairs.rows[p].length;
            if (results.pressure[p] > r.max_pressure)
              {
                r.max_pressure  = results.pressure[p];
                r.peak_location = pairs.points[p].position;
              }
          }
        r.centre_of_pressure += contact.lambda[p] * pairs.points[p].position;
      }
    for (InterfaceResult<dim> &r : results.interfaces)
      {
        if (r.force > 0)
          r.centre_of_pressure /= r.force;
        else
          r.centre_of_pressure = Point<dim>();
        r.mean_pressure = r.contact_length > 0 ? r.force / r.contact_length : 0;
      }
    return results;
  }


  template Results<2>
  compute_results(const ProblemAccess<2> &);
  template Results<3>
  compute_results(const ProblemAccess<3> &);
} // namespace knee_contact
