// The weights of a whole mesh's cells for the partition of a parallel run:
// partition_weights().
#include <knee_contact/contact/contact.h>
#include <knee_contact/contact/search.h>

#include <algorithm>
#include <map>
#include <vector>

namespace knee_contact
{
  template <int dim>
  std::vector<double>
  partition_weights(const Triangulation<dim> &whole,
                    const ContactInterfaces  &interfaces)
  {
    AssertThrow(whole.n_levels() == 1, ExcInternalError());
    const unsigned int n_vertices = whole.n_vertices();
    // Each cell's vertices and the cells at each vertex (compressed rows;
    // iterators over 2e6 cells took longer than the rest).
    const unsigned int        n_cells = whole.n_active_cells();
    std::vector<unsigned int> vertices_start(n_cells + 1, 0), vertices_of;
    for (const auto &cell : whole.active_cell_iterators())
      {
        for (const unsigned int v : cell->vertex_indices())
          vertices_of.push_back(cell->vertex_index(v));
        vertices_start[cell->active_cell_index() + 1] = vertices_of.size();
      }
    std::vector<unsigned int> cells_start(n_vertices + 1, 0), cells_at;
    for (const unsigned int v : vertices_of)
      ++cells_start[v + 1];
    for (unsigned int v = 0; v < n_vertices; ++v)
      cells_start[v + 1] += cells_start[v];
    cells_at.resize(cells_start.back());
    {
      std::vector<unsigned int> next(cells_start.begin(),
                                     cells_start.end() - 1);
      for (unsigned int c = 0; c < n_cells; ++c)
        for (unsigned int k = vertices_start[c]; k < vertices_start[c + 1]; ++k)
          cells_at[next[vertices_of[k]]++] = c;
    }
    // f(w) for each vertex w of the cells at v (repeated).
    const auto for_each_near = [&](const unsigned int v, const auto &f) {
      for (unsigned int k = cells_start[v]; k < cells_start[v + 1]; ++k)
        for (unsigned int l = vertices_start[cells_at[k]];
             l < vertices_start[cells_at[k] + 1];
             ++l)
          f(vertices_of[l]);
    };
    // A vertex's row of the mesh's pattern: the vertices of its cells.
    const auto row = [&](const unsigned int v) {
      std::vector<unsigned int> columns;
      for_each_near(v, [&](const unsigned int w) { columns.push_back(w); });
      std::sort(columns.begin(), columns.end());
      columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
      return columns;
    };

    // The vertices each slave vertex's row refers to (E(s) of
    // ActiveSetSolver's pattern, by vertex): itself and the vertices of the
    // master faces near its faces: mortar_rows()'s candidates (the faces
    // meeting a slave face's box grown by the distance to the nearest, at
    // most the maximum gap) whose discs meet the slave face's along it.
    std::map<unsigned int, std::vector<unsigned int>> refers;
    // A face's centre and its largest distance from it (its vertices lie in
    // the disc of that radius).
    const auto disc = [&](const std::vector<unsigned int> &face) {
      Point<dim> centre;
      for (const unsigned int v : face)
        centre += whole.get_vertices()[v] / double(face.size());
      double radius = 0;
      for (const unsigned int v : face)
        radius = std::max(radius, centre.distance(whole.get_vertices()[v]));
      return std::make_pair(centre, radius);
    };
    // The faces of every contact side, by boundary id, in one pass.
    std::map<types::boundary_id, std::vector<std::vector<unsigned int>>>
      side_faces;
    for (const ContactInterface &interface : interfaces.interfaces())
      {
        side_faces[interface.slave_id];
        side_faces[interface.master_id];
      }
    for (const auto &cell : whole.active_cell_iterators())
      for (const unsigned int f : cell->face_indices())
        if (cell->face(f)->at_boundary())
          if (const auto side = side_faces.find(cell->face(f)->boundary_id());
              side != side_faces.end())
            {
              std::vector<unsigned int> face;
              for (const unsigned int v : cell->face(f)->vertex_indices())
                face.push_back(cell->face(f)->vertex_index(v));
              side->second.push_back(std::move(face));
            }
    const auto points_of = [&](const std::vector<unsigned int> &face) {
      std::vector<Point<dim>> points;
      for (const unsigned int v : face)
        points.push_back(whole.get_vertices()[v]);
      return points;
    };
    for (const ContactInterface &interface : interfaces.interfaces())
      {
        const auto &master_faces = side_faces[interface.master_id];
        if (master_faces.empty())
          continue;
        std::vector<BoundingBox<dim>>              master_boxes;
        std::vector<std::pair<Point<dim>, double>> master_discs;
        for (const auto &face : master_faces)
          {
            master_boxes.emplace_back(points_of(face));
            master_discs.push_back(disc(face));
          }
        const ContactSearch<dim> search(master_boxes);
        for (const auto &face : side_faces[interface.slave_id])
          {
            const std::vector<Point<dim>> points = points_of(face);
            // The face's unit normal: the masters it faces are those whose
            // discs meet its disc along the face (the clipping of
            // mortar_rows() keeps the overlapping ones).
            Tensor<1, dim> normal;
            if constexpr (dim == 2)
              normal = cross_product_2d(points[1] - points[0]);
            else
              normal =
                cross_product_3d(points[1] - points[0], points[2] - points[0]);
            normal /= std::max(normal.norm(), 1e-300);
            const auto [centre, radius] = disc(face);
            std::vector<unsigned int> masters;
            for (const unsigned int m : search.near(
                   BoundingBox<dim>(points), centre, 0., interface.maximum_gap))
              {
                const auto &[master_centre, master_radius] = master_discs[m];
                Tensor<1, dim> along = master_centre - centre;
                along -= (along * normal) * normal;
                if (along.norm() < radius + master_radius)
                  masters.insert(masters.end(),
                                 master_faces[m].begin(),
                                 master_faces[m].end());
              }
            for (const unsigned int s : face)
              {
                auto &e = refers[s];
                if (e.empty())
                  e.push_back(s);
                e.insert(e.end(), masters.begin(), masters.end());
              }
          }
      }
    for (auto &[s, e] : refers)
      {
        std::sort(e.begin(), e.end());
        e.erase(std::unique(e.begin(), e.end()), e.end());
      }

    // Each vertex's entries: its mesh row's, or (a vertex whose row the
    // contact rows widen: near a slave, or referred to by one) as
    // ActiveSetSolver's pattern expands it: the row's columns each replaced
    // by what it refers to, and a slave's row added to every vertex it
    // refers to instead of its own.
    std::vector<bool> widens(n_vertices, false);
    for (const auto &[s, e] : refers)
      {
        for_each_near(s, [&](const unsigned int w) { widens[w] = true; });
        for (const unsigned int a : e)
          widens[a] = true;
      }
    std::vector<double>                               entries(n_vertices, 0);
    std::map<unsigned int, std::vector<unsigned int>> widened;
    // A master vertex gathers the rows of every slave that refers to it,
    // mostly the same columns: sorted and made unique whenever it doubled,
    // so that it holds at most about twice its row.
    std::map<unsigned int, std::size_t> compacted;
    const auto                          add = [&](const unsigned int               a,
                         const std::vector<unsigned int> &columns) {
      auto &w = widened[a];
      w.insert(w.end(), columns.begin(), columns.end());
      auto &size = compacted[a];
      if (w.size() > 2 * size + 256)
        {
          std::sort(w.begin(), w.end());
          w.erase(std::unique(w.begin(), w.end()), w.end());
          size = w.size();
        }
    };
    // The others' rows counted, not sorted: a vertex seen from v is marked
    // with v.
    std::vector<unsigned int> seen_from(n_vertices,
                                        numbers::invalid_unsigned_int);
    for (unsigned int v = 0; v < n_vertices; ++v)
      {
        if (!widens[v])
          {
            for_each_near(v, [&](const unsigned int w) {
              if (seen_from[w] != v)
                {
                  seen_from[w] = v;
                  ++entries[v];
                }
            });
            continue;
          }
        const std::vector<unsigned int> columns = row(v);
        std::vector<unsigned int>       expanded;
        for (const unsigned int j : columns)
          if (const auto e = refers.find(j); e != refers.end())
            expanded.insert(expanded.end(), e->second.begin(), e->second.end());
          else
            expanded.push_back(j);
        if (const auto e = refers.find(v); e != refers.end())
          for (const unsigned int a : e->second)
            add(a, expanded);
        else
          add(v, expanded);
      }
    for (auto &[a, w] : widened)
      {
        std::sort(w.begin(), w.end());
        entries[a] = std::unique(w.begin(), w.end()) - w.begin();
      }

    // A cell's share of its vertices' rows.
    std::vector<double> weights(n_cells, 0);
    for (unsigned int c = 0; c < n_cells; ++c)
      for (unsigned int k = vertices_start[c]; k < vertices_start[c + 1]; ++k)
        {
          const unsigned int v = vertices_of[k];
          weights[c] += entries[v] / (cells_start[v + 1] - cells_start[v]);
        }
    return weights;
  }

  template std::vector<double>
  partition_weights(const Triangulation<2> &, const ContactInterfaces &);
  template std::vector<double>
  partition_weights(const Triangulation<3> &, const ContactInterfaces &);

} // namespace knee_contact
