#include <knee_contact/core/scene_checks.h>

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/qprojector.h>
#include <deal.II/base/quadrature_lib.h>

#include <deal.II/lac/vector.h>

#include <deal.II/fe/mapping.h>
#include <deal.II/grid/grid_tools.h>
#include <deal.II/numerics/rtree.h>

#include <boost/geometry/index/rtree.hpp>

#include <cmath>
#include <iomanip>
#include <numeric>
#include <set>
#include <sstream>

namespace knee_contact
{
  namespace scene_checks
  {
    namespace
    {
      template <int dim>
      std::string
      at(const Point<dim> &p)
      {
        std::ostringstream out;
        out << std::setprecision(6);
        for (unsigned int d = 0; d < dim; ++d)
          out << (d == 0 ? "(" : ", ") << p[d];
        out << ")";
        return out.str();
      }

      std::string
      type_name(const BoundaryType type)
      {
        switch (type)
          {
            case BoundaryType::displacement:
              return "displacement";
            case BoundaryType::traction:
              return "traction";
            case BoundaryType::pressure:
              return "pressure";
            default:
              return "sliding";
          }
      }
    } // namespace



    template <int dim>
    void
    check_roles(const BoundaryConditions<dim> &conditions,
                const ContactInterfaces       &interfaces)
    {
      for (const auto &interface : interfaces.interfaces())
        for (const auto id : {interface.slave_id, interface.master_id})
          for (const auto &condition : conditions.conditions())
            AssertThrow(condition.ids.count(id) == 0,
                        ExcMessage(
                          condition.name + "/Boundary ids: boundary id " +
                          std::to_string(id) + " is a contact side of '" +
                          interface.name + "' and cannot also carry a " +
                          type_name(condition.type) +
                          " condition (one role per boundary id)"));
    }



    template <int dim>
    void
    check_finite_data(const Triangulation<dim>      &triangulation,
                      const Materials<dim>          &materials,
                      const BoundaryConditions<dim> &conditions)
    {
      Vector<double> values(dim);
      const auto     check = [&](const Function<dim> &function,
                             const Point<dim>    &p,
                             const std::string   &parameter,
                             const std::string   &where) {
        function.vector_value(p, values);
        for (unsigned int c = 0; c < function.n_components; ++c)
          AssertThrow(std::isfinite(values(c)),
                      ExcMessage(parameter + ": not finite (inf or nan) at " +
                                 (dim == 2 ? "(x, y) = " : "(x, y, z) = ") +
                                 at(p) + where));
      };
      // A function written as numbers is the same everywhere: checked on
      // the first cell it applies to (evaluating it at every vertex and
      // Gauss point took 4.2 s on a mesh of 2.0e6 tetrahedra).
      std::set<const Function<dim> *> constants_checked;
      const auto to_check = [&](const Function<dim> &f, const bool constant) {
        return !constant || constants_checked.insert(&f).second;
      };
      for (const auto &cell : triangulation.active_cell_iterators())
        {
          const Material<dim> &material = materials[cell->material_id()];
          const auto          &force    = *material.body_force;
          const ReferenceCell  kind     = cell->reference_cell();
          const auto          &mapping =
            kind.template get_default_linear_mapping<dim, dim>();
          if (to_check(force, material.body_force_is_constant))
            {
              const std::string parameter =
                "Materials (material '" + material.name + "')/Body force";
              for (const auto v : cell->vertex_indices())
                check(force, cell->vertex(v), parameter, "");
              // The Gauss points, mapped as the assembly maps them. (The
              // rule is kept in a named variable: a range-for over a
              // member of a temporary would read freed stack memory.)
              const Quadrature<dim> cell_points =
                kind.template get_gauss_type_quadrature<dim>(2);
              for (const auto &xi : cell_points.get_points())
                check(force,
                      mapping.transform_unit_to_real_cell(cell, xi),
                      parameter,
                      "");
            }
          for (const auto f : cell->face_indices())
            if (cell->face(f)->at_boundary())
              for (const auto &condition : conditions.conditions())
                if (condition.function &&
                    condition.ids.count(cell->face(f)->boundary_id()) != 0 &&
                    to_check(*condition.function, condition.constant))
                  {
                    const std::string where =
                      " on boundary id " +
                      std::to_string(cell->face(f)->boundary_id());
                    for (const auto v : cell->face(f)->vertex_indices())
                      check(*condition.function,
                            cell->face(f)->vertex(v),
                            condition.name + "/Value",
                            where);
                    // The face's Gauss points, as the assembly places them.
                    const Quadrature<dim> face_points =
                      QProjector<dim>::project_to_face(
                        kind,
                        kind.face_reference_cell(f)
                          .template get_gauss_type_quadrature<dim - 1>(2),
                        f);
                    for (const auto &xi : face_points.get_points())
                      check(*condition.function,
                            mapping.transform_unit_to_real_cell(cell, xi),
                            condition.name + "/Value",
                            where);
                  }
        }
    }



    template <int dim>
    void
    check_joints(const Triangulation<dim>        &triangulation,
                 const std::vector<unsigned int> &body_of_cell)
    {
      if constexpr (dim == 2)
        check_cracks(triangulation, body_of_cell);

      // Around each vertex, the cells that share it must be connected
      // through faces that contain it. (3D: two bodies that share only an
      // edge pass; they are joined along a line, which a bonded solid does
      // not mean either.) The cells at each vertex in one flat array
      // (GridTools::vertex_to_cell_map keeps a std::set per vertex and took
      // a quarter of reading a 4.5e5-tetrahedron mesh, measured), and one
      // union-find over its slots: each interior face joins its two cells
      // at each of its vertices (visiting the faces around every vertex
      // instead took 4.5 s of 22 reading a mesh of 1.5e6 tetrahedra). The
      // mesh here is as read or globally refined, without hanging
      // vertices, so a cell's vertices are all the vertices it touches.
      AssertThrow(!triangulation.has_hanging_nodes(), ExcInternalError());
      const unsigned int        n_vertices = triangulation.n_vertices();
      const unsigned int        n_cells    = triangulation.n_active_cells();
      std::vector<unsigned int> start(n_vertices + 1, 0);
      // Each cell's vertices from first_corner[c] on (cells of all kinds),
      // read once: the accessors' cost dominated the check.
      std::vector<unsigned int> first_corner(n_cells + 1, 0);
      for (const auto &cell : triangulation.active_cell_iterators())
        first_corner[cell->active_cell_index() + 1] = cell->n_vertices();
      std::partial_sum(first_corner.begin(),
                       first_corner.end(),
                       first_corner.begin());
      std::vector<unsigned int> corner_vertex(first_corner.back());
      for (const auto &cell : triangulation.active_cell_iterators())
        for (const auto k : cell->vertex_indices())
          {
            const unsigned int v = cell->vertex_index(k);
            corner_vertex[first_corner[cell->active_cell_index()] + k] = v;
            ++start[v + 1];
          }
      std::partial_sum(start.begin(), start.end(), start.begin());
      // The slot of each (cell, corner) among the cells at its vertex.
      std::vector<unsigned int> slot_of_corner(first_corner.back());
      {
        std::vector<unsigned int> next(start.begin(), start.end() - 1);
        for (unsigned int c = 0; c < first_corner.back(); ++c)
          slot_of_corner[c] = next[corner_vertex[c]]++;
      }
      std::vector<unsigned int> parent(start.back());
      std::iota(parent.begin(), parent.end(), 0);
      const auto find = [&](unsigned int i) {
        while (parent[i] != i)
          i = parent[i] = parent[parent[i]];
        return i;
      };
      // All active cells on the finest level (a mesh as read or globally
      // refined): a neighbour's level index is its active index.
      const unsigned int finest = triangulation.n_levels() - 1;
      const bool         one_level =
        triangulation.n_cells(finest) == triangulation.n_active_cells();
      for (const auto &cell : triangulation.active_cell_iterators())
        {
          const unsigned int  c    = cell->active_cell_index();
          const ReferenceCell kind = cell->reference_cell();
          for (const auto f : cell->face_indices())
            {
              // -1: no neighbour (the boundary).
              const int index = cell->neighbor_index(f);
              if (index < 0)
                continue;
              const unsigned int n = one_level
                                       ? unsigned(index)
                                       : cell->neighbor(f)->active_cell_index();
              if (n < c)
                continue;
              for (unsigned int k = 0;
                   k < kind.face_reference_cell(f).n_vertices();
                   ++k)
                {
                  const unsigned int corner =
                    first_corner[c] + kind.face_to_cell_vertices(f, k, 1);
                  for (unsigned int j = first_corner[n];
                       j < first_corner[n + 1];
                       ++j)
                    if (corner_vertex[j] == corner_vertex[corner])
                      {
                        const unsigned int here = find(slot_of_corner[corner]);
                        parent[here]            = find(slot_of_corner[j]);
                      }
                }
            }
        }
      for (unsigned int v = 0; v < n_vertices; ++v)
        {
          if (start[v + 1] - start[v] < 2)
            continue;
          unsigned int n_groups = 0;
          for (unsigned int i = start[v]; i < start[v + 1]; ++i)
            n_groups += find(i) == i;
          AssertThrow(n_groups == 1,
                      ExcMessage("Mesh: cells meet only at the vertex " +
                                 at(triangulation.get_vertices()[v]) +
                                 (dim == 2 ? ", not along an edge (bodies "
                                             "joined at a single point); "
                                             "bonded parts must share an "
                                             "edge"
                                           : ", not along a face (bodies "
                                             "joined at a single point); "
                                             "bonded parts must share a "
                                             "face") +
                                 ", parts in contact must not share "
                                 "vertices"));
        }
    }



    void
    check_cracks(const Triangulation<2>          &triangulation,
                 const std::vector<unsigned int> &body_of_cell)
    {
      // Boundary edges of one body on top of each other: a crack where
      // bonded edges do not match. Found through an R-tree of the boundary
      // faces' bounding boxes.
      struct Edge
      {
        Point<2>     a, b;
        unsigned int body;
      };
      std::vector<Edge>                                    edges;
      std::vector<std::pair<BoundingBox<2>, unsigned int>> boxes;
      for (const auto &cell : triangulation.active_cell_iterators())
        for (const auto f : cell->face_indices())
          if (cell->face(f)->at_boundary())
            {
              const Edge e{cell->face(f)->vertex(0),
                           cell->face(f)->vertex(1),
                           body_of_cell[cell->active_cell_index()]};
              boxes.emplace_back(
                BoundingBox<2>(std::vector<Point<2>>{e.a, e.b}), edges.size());
              edges.push_back(e);
            }
      const auto tree = pack_rtree(boxes);
      for (unsigned int i = 0; i < edges.size(); ++i)
        {
          const Edge        &e      = edges[i];
          const Tensor<1, 2> t      = e.b - e.a;
          const double       length = t.norm();
          const double       tol    = 1e-8 * length;
          std::vector<std::pair<BoundingBox<2>, unsigned int>> near;
          tree.query(boost::geometry::index::intersects(boxes[i].first),
                     std::back_inserter(near));
          for (const auto &[box, j] : near)
            {
              if (j <= i || edges[j].body != e.body)
                continue;
              const Edge &o = edges[j];
              // Collinear and overlapping along a positive length.
              const auto offset = [&](const Point<2> &p) {
                return std::abs(t[0] * (p - e.a)[1] - t[1] * (p - e.a)[0]) /
                       length;
              };
              if (offset(o.a) > tol || offset(o.b) > tol)
                continue;
              const double s0      = (o.a - e.a) * t / length,
                           s1      = (o.b - e.a) * t / length;
              const double overlap = std::min(length, std::max(s0, s1)) -
                                     std::max(0., std::min(s0, s1));
              AssertThrow(overlap <= tol,
                          ExcMessage(
                            "Mesh: two boundary edges of body " +
                            std::to_string(e.body) +
                            " lie on top of each "
                            "other near " +
                            at(e.a + 0.5 * t) +
                            ": bonded edges whose vertices do not match (a "
                            "crack); make the vertices match or use "
                            "different groups and a contact interface"));
            }
        }
    }



    template void
    check_roles(const BoundaryConditions<2> &, const ContactInterfaces &);
    template void
    check_roles(const BoundaryConditions<3> &, const ContactInterfaces &);
    template void
    check_finite_data(const Triangulation<2> &,
                      const Materials<2> &,
                      const BoundaryConditions<2> &);
    template void
    check_finite_data(const Triangulation<3> &,
                      const Materials<3> &,
                      const BoundaryConditions<3> &);
    template void
    check_joints(const Triangulation<2> &, const std::vector<unsigned int> &);
    template void
    check_joints(const Triangulation<3> &, const std::vector<unsigned int> &);
  } // namespace scene_checks
} // namespace knee_contact
