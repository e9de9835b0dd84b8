#include <knee_contact/base/input.h>
#include <knee_contact/physics/rigid_motions.h>

#include <deal.II/base/exceptions.h>
#include <deal.II/base/symmetric_tensor.h>

#include <deal.II/fe/fe.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>

namespace knee_contact
{
  template <int dim>
  void
  RigidMotions<dim>::add_parameters(ParameterHandler  &prm,
                                    const unsigned int n_subsections)
  {
    prm.enter_subsection("Load cases");
    prm.add_parameter(
      "Number of motions",
      n_motions,
      "How many subsections 'Motion 0', 'Motion 1', ... follow. A motion "
      "places bodies rigidly in each load case (a flexion, a translation): "
      "the mesh of a case is the scene's with those bodies at the case's "
      "pose, the contact pairs are found there, and with friction the slip "
      "counts the rigid sliding. See doc/load-cases.md.",
      Patterns::Integer(0, 255));
    entries.clear();
    entries.resize(n_subsections);
    for (unsigned int m = 0; m < n_subsections; ++m)
      {
        Entry &entry = entries[m];
        prm.enter_subsection("Motion " + std::to_string(m));
        prm.add_parameter("Material ids",
                          entry.ids,
                          "The material ids of the cells this motion moves "
                          "(whole bodies: no vertex of them may be shared "
                          "with a cell it does not move).",
                          Patterns::List(Patterns::Integer(0, 254)));
        prm.add_parameter("Rotation axis",
                          entry.axis,
                          "3D: the direction of the rotation axis (x; y; z, "
                          "any length but zero). In 2D the rotation is in "
                          "the plane and this stays 0; 0; 1.",
                          input::expression_pattern(3));
        prm.add_parameter("Rotation centre",
                          entry.centre,
                          "A point on the axis [m] (x; y[; z]).",
                          input::expression_pattern(3));
        prm.add_parameter("Rotation angle",
                          entry.angle,
                          "theta(t) [degrees], an expression in the load "
                          "parameter t, counter-clockwise about the axis.",
                          input::expression_pattern(1));
        prm.add_parameter("Translation",
                          entry.translation,
                          "d(t) [m] (x; y[; z]), expressions in t, added "
                          "after the rotation: P_t(X) = c + R(theta(t)) "
                          "(X - c) + d(t).",
                          input::expression_pattern(3));
        prm.leave_subsection();
      }
    prm.leave_subsection();
  }



  template <int dim>
  void
  RigidMotions<dim>::check_parameters(const std::vector<double> &t)
  {
    motions.clear();
    std::map<types::material_id, std::string> moved;
    for (unsigned int m = 0; m < entries.size(); ++m)
      {
        const Entry &entry = entries[m];
        Motion       motion;
        motion.name = "Load cases/Motion " + std::to_string(m);
        AssertThrow(!entry.ids.empty(),
                    ExcMessage(motion.name + "/Material ids: empty list"));
        for (const unsigned int id : entry.ids)
          {
            const auto material = static_cast<types::material_id>(id);
            AssertThrow(moved.find(material) == moved.end(),
                        ExcMessage(motion.name + "/Material ids: material id " +
                                   std::to_string(id) +
                                   " is already moved by " + moved[material]));
            moved[material] = motion.name;
            motion.ids.push_back(material);
          }
        // Constant vectors: each component a constant expression.
        const auto constant_vector = [&](const std::string &text,
                                         const std::string &entry_name,
                                         const unsigned int n) {
          const std::string parameter = motion.name + "/" + entry_name;
          const auto        parts     = input::split(text, ';');
          AssertThrow(parts.size() == n,
                      ExcMessage("parameter '" + parameter + "': expected " +
                                 std::to_string(n) +
                                 " components separated by ';', got '" + text +
                                 "'"));
          std::vector<double> values;
          for (const auto &part : parts)
            values.push_back(input::evaluate_constant(part, parameter));
          return values;
        };
        const auto axis = constant_vector(entry.axis, "Rotation axis", 3);
        for (unsigned int d = 0; d < 3; ++d)
          motion.axis[d] = axis[d];
        if (dim == 2)
          AssertThrow(axis[0] == 0 && axis[1] == 0 && axis[2] != 0,
                      ExcMessage("parameter '" + motion.name +
                                 "/Rotation axis': a 2D rotation is about z "
                                 "(0; 0; 1), not '" +
                                 entry.axis + "'"));
        AssertThrow(motion.axis.norm() > 0,
                    ExcMessage("parameter '" + motion.name +
                               "/Rotation axis': the zero vector"));
        motion.axis /= motion.axis.norm();
        const auto centre =
          constant_vector(entry.centre, "Rotation centre", dim);
        for (unsigned int d = 0; d < dim; ++d)
          motion.centre[d] = centre[d];
        motion.angle = input::parse_expression<dim>(
          entry.angle, 1, motion.name + "/Rotation angle", "", true);
        motion.translation = input::parse_expression<dim>(
          entry.translation, dim, motion.name + "/Translation", "", true);
        motions.push_back(std::move(motion));
      }
    // Each case's pose is finite and, expressions in t alone, one rigid
    // motion of the body.
    Point<dim> elsewhere;
    for (unsigned int d = 0; d < dim; ++d)
      elsewhere[d] = 0.5 + d;
    for (const auto &motion : motions)
      for (const double t_case : t)
        {
          pose(&motion - motions.data(), t_case);
          for (const auto &[function, entry_name] :
               {std::make_pair(motion.angle.get(), "Rotation angle"),
                std::make_pair(motion.translation.get(), "Translation")})
            for (unsigned int c = 0; c < function->n_components; ++c)
              AssertThrow(function->value(Point<dim>(), c) ==
                            function->value(elsewhere, c),
                          ExcMessage("parameter '" + motion.name + "/" +
                                     entry_name +
                                     "': an expression in t alone (x, y "
                                     "and z would make the motion "
                                     "non-rigid)"));
        }
  }



  template <int dim>
  unsigned int
  RigidMotions<dim>::motion_of(const types::material_id id) const
  {
    for (unsigned int m = 0; m < motions.size(); ++m)
      if (std::find(motions[m].ids.begin(), motions[m].ids.end(), id) !=
          motions[m].ids.end())
        return m;
    return none;
  }



  template <int dim>
  void
  RigidMotions<dim>::check_mesh(const Triangulation<dim> &triangulation) const
  {
    if (motions.empty())
      return;
    std::set<types::material_id> present;
    std::vector<unsigned int>    motion_of_vertex(triangulation.n_vertices());
    std::vector<bool>            seen(triangulation.n_vertices(), false);
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        present.insert(cell->material_id());
        const unsigned int m = motion_of(cell->material_id());
        for (const unsigned int v : cell->vertex_indices())
          {
            unsigned int &owner = motion_of_vertex[cell->vertex_index(v)];
            if (!seen[cell->vertex_index(v)])
              {
                seen[cell->vertex_index(v)] = true;
                owner                       = m;
              }
            AssertThrow(
              owner == m,
              ExcMessage((m != none ? motions[m].name : motions[owner].name) +
                         "/Material ids: the cells of material id " +
                         std::to_string(cell->material_id()) +
                         " share the vertex at " + point_text(cell->vertex(v)) +
                         " with cells that move otherwise; a motion moves "
                         "whole bodies (bonded materials move together)"));
          }
      }
    for (const auto &motion : motions)
      for (const auto id : motion.ids)
        AssertThrow(present.count(id) > 0,
                    ExcMessage(motion.name +
                               "/Material ids: the mesh has no "
                               "cells of material id " +
                               std::to_string(id)));
  }



  template <int dim>
  std::pair<Tensor<2, dim>, Tensor<1, dim>>
  RigidMotions<dim>::pose(const unsigned int m, const double t) const
  {
    const Motion &motion = motions[m];
    motion.angle->set_time(t);
    motion.translation->set_time(t);
    const double theta = motion.angle->value(Point<dim>()) * numbers::PI / 180.;
    Tensor<1, dim> d;
    for (unsigned int i = 0; i < dim; ++i)
      d[i] = motion.translation->value(Point<dim>(), i);
    AssertThrow(std::isfinite(theta) && std::isfinite(d.norm()),
                ExcMessage(motion.name +
                           ": the rotation angle or the "
                           "translation is not finite at t = " +
                           input::format(t)));
    // Rodrigues' formula, R = cos I + sin [a]x + (1 - cos) a a^T; in 2D its
    // upper left block for a = e_z.
    const double   c = std::cos(theta), s = std::sin(theta);
    const auto    &a           = motion.axis;
    const double   cross[3][3] = {{0, -a[2], a[1]},
                                  {a[2], 0, -a[0]},
                                  {-a[1], a[0], 0}};
    Tensor<2, dim> r;
    for (unsigned int i = 0; i < dim; ++i)
      for (unsigned int j = 0; j < dim; ++j)
        r[i][j] = (i == j ? c : 0.) + s * cross[i][j] + (1 - c) * a[i] * a[j];
    return {r, d};
  }



  template <int dim>
  Point<dim>
  RigidMotions<dim>::transfer(const unsigned int m,
                              const Point<dim>  &x,
                              const double       t_from,
                              const double       t_to) const
  {
    if (m == none)
      return x;
    const Point<dim> &c         = motions[m].centre;
    Point<dim>        reference = x;
    if (!std::isnan(t_from))
      {
        const auto [r, d] = pose(m, t_from);
        reference         = c + transpose(r) * (x - c - d);
      }
    const auto [r, d] = pose(m, t_to);
    return c + r * (reference - c) + d;
  }



  template <int dim>
  void
  RigidMotions<dim>::move(Triangulation<dim> &triangulation,
                          const double        t_from,
                          const double        t_to) const
  {
    if (motions.empty())
      return;
    std::vector<bool> moved(triangulation.n_vertices(), false);
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int m = motion_of(cell->material_id());
        if (m == none)
          continue;
        for (const unsigned int v : cell->vertex_indices())
          if (!moved[cell->vertex_index(v)])
            {
              moved[cell->vertex_index(v)] = true;
              cell->vertex(v) = transfer(m, cell->vertex(v), t_from, t_to);
            }
      }
  }



  template <int dim>
  Tensor<2, dim>
  RigidMotions<dim>::rotation_change(const unsigned int motion,
                                     const double       t_from,
                                     const double       t_to) const
  {
    if (motion == none)
      return Tensor<2, dim>(unit_symmetric_tensor<dim>());
    return pose(motion, t_to).first * transpose(pose(motion, t_from).first);
  }



  template <int dim>
  std::vector<unsigned int>
  RigidMotions<dim>::motion_of_dofs(const DoFHandler<dim> &dof_handler) const
  {
    std::vector<unsigned int> motion(dof_handler.n_dofs(), none);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        const unsigned int m = motion_of(cell->material_id());
        if (m != none)
          for (const unsigned int v : cell->vertex_indices())
            for (unsigned int d = 0; d < dim; ++d)
              motion[cell->vertex_dof_index(v, d)] = m;
      }
    return motion;
  }



  template <int dim>
  void
  RigidMotions<dim>::rotate_displacements(const DoFHandler<dim> &dof_handler,
                                          const double           t_from,
                                          const double           t_to,
                                          Vector<double>        &u) const
  {
    std::vector<Tensor<2, dim>> change;
    for (unsigned int m = 0; m < motions.size(); ++m)
      change.push_back(rotation_change(m, t_from, t_to));
    std::vector<bool> done(dof_handler.n_dofs(), false);
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        const unsigned int m = motion_of(cell->material_id());
        if (m == none)
          continue;
        for (const unsigned int v : cell->vertex_indices())
          {
            // The vertex's dofs, component by component (FE_Q(1)^dim and
            // P1^dim have one per component at each vertex).
            std::array<types::global_dof_index, dim> dofs;
            for (unsigned int d = 0; d < dim; ++d)
              dofs[d] = cell->vertex_dof_index(v, d);
            if (done[dofs[0]])
              continue;
            done[dofs[0]] = true;
            Tensor<1, dim> value;
            for (unsigned int d = 0; d < dim; ++d)
              value[d] = u[dofs[d]];
            value = change[m] * value;
            for (unsigned int d = 0; d < dim; ++d)
              u[dofs[d]] = value[d];
          }
      }
  }



  template <int dim>
  Tensor<1, dim>
  RigidMotions<dim>::relative_motion(const unsigned int slave,
                                     const unsigned int master,
                                     const Point<dim>  &x,
                                     const double       t_from,
                                     const double       t_to) const
  {
    return transfer(master, x, t_to, t_from) - transfer(slave, x, t_to, t_from);
  }



  template class RigidMotions<2>;
  template class RigidMotions<3>;
} // namespace knee_contact
