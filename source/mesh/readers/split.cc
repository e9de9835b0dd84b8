#include <knee_contact/base/input.h>
#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <vector>

namespace knee_contact
{
  namespace mesh_readers
  {
    using namespace internal;

    void
    split_into_quadrilaterals(
      Description<2>                               &mesh,
      const std::map<types::boundary_id, Point<2>> &circles)
    {
      // Each edge gets one midpoint, shared by the cells beside it, so the
      // split mesh is conforming.
      std::map<std::pair<unsigned int, unsigned int>, unsigned int> midpoint;
      const auto middle = [&](const unsigned int a, const unsigned int b) {
        const auto key = std::minmax(a, b);
        const auto it  = midpoint.find(key);
        if (it != midpoint.end())
          return it->second;
        midpoint[key] = mesh.vertices.size();
        mesh.vertices.push_back(0.5 * (mesh.vertices[a] + mesh.vertices[b]));
        return static_cast<unsigned int>(mesh.vertices.size() - 1);
      };

      std::vector<CellData<2>> cells;
      for (const CellData<2> &cell : mesh.cells)
        {
          const auto &v = cell.vertices;
          // Corners in counter-clockwise order.
          std::vector<unsigned int> ring =
            v.size() == 3 ? std::vector<unsigned int>{v[0], v[1], v[2]}
                          : std::vector<unsigned int>{v[0], v[1], v[3], v[2]};
          Point<2> centre;
          for (const unsigned int k : ring)
            centre += mesh.vertices[k] / double(ring.size());
          const unsigned int c = mesh.vertices.size();
          mesh.vertices.push_back(centre);
          for (unsigned int k = 0; k < ring.size(); ++k)
            {
              const unsigned int next = ring[(k + 1) % ring.size()],
                                 prev =
                                   ring[(k + ring.size() - 1) % ring.size()];
              CellData<2> child(4);
              // Round the child counter-clockwise: corner, midpoint to the
              // next corner, centre, midpoint to the previous one; deal.II
              // lists them lexicographically (0 1 3 2 round the cell).
              child.vertices    = {ring[k],
                                   middle(ring[k], next),
                                   middle(prev, ring[k]),
                                   c};
              child.material_id = cell.material_id;
              child.manifold_id = cell.manifold_id;
              cells.push_back(child);
            }
        }
      mesh.cells = std::move(cells);

      std::vector<CellData<1>> lines;
      for (const CellData<1> &line : mesh.subcells.boundary_lines)
        {
          const auto key = std::minmax(line.vertices[0], line.vertices[1]);
          const auto it  = midpoint.find(key);
          if (it == midpoint.end())
            continue; // not an edge of the mesh: deal.II would refuse it
          const auto circle = circles.find(line.boundary_id);
          if (circle != circles.end())
            {
              // On the arc, not on its chord.
              const Point<2> &c = circle->second;
              const double    r = mesh.vertices[line.vertices[0]].distance(c);
              const Tensor<1, 2> d = mesh.vertices[it->second] - c;
              if (d.norm() > 0)
                mesh.vertices[it->second] = c + r / d.norm() * d;
            }
          for (const unsigned int end : {0u, 1u})
            {
              CellData<1> half = line;
              half.vertices    = {line.vertices[end], it->second};
              lines.push_back(half);
            }
        }
      mesh.subcells.boundary_lines = std::move(lines);
    }



    void
    split_into_hexahedra(Description<3> &mesh)
    {
      // Every new vertex is the mean of a set of the old ones (an edge's
      // two, a face's three or four, a cell's four or eight), made once per
      // set: cells that share an edge or a face share its new vertices, so
      // the split mesh is conforming.
      std::map<std::vector<unsigned int>, unsigned int> made;
      const auto mean = [&](std::vector<unsigned int> of) {
        std::sort(of.begin(), of.end());
        if (of.size() == 1)
          return of[0];
        const auto [it, inserted] = made.try_emplace(of, 0u);
        if (inserted)
          {
            Point<3> sum;
            for (const unsigned int k : of)
              sum += mesh.vertices[k];
            it->second = mesh.vertices.size();
            mesh.vertices.push_back(sum / double(of.size()));
          }
        return it->second;
      };
      // A hexahedron with an edge of a tetrahedron would meet its pieces at
      // the edge's midpoint (a hanging vertex): refused. Bodies in contact
      // share no vertices; one body of both kinds needs pyramids between
      // them, which are not read.
      std::set<std::pair<unsigned int, unsigned int>> tetrahedron_edges;
      for (const CellData<3> &cell : mesh.cells)
        if (cell.vertices.size() == 4)
          for (unsigned int a = 0; a < 4; ++a)
            for (unsigned int b = a + 1; b < 4; ++b)
              tetrahedron_edges.insert(
                std::minmax(cell.vertices[a], cell.vertices[b]));
      for (const CellData<3> &cell : mesh.cells)
        if (cell.vertices.size() == 8)
          for (unsigned int a = 0; a < 8; ++a)
            for (unsigned int axis = 0; axis < 3; ++axis)
              if (((a >> axis) & 1u) == 0)
                {
                  const auto edge =
                    std::minmax(cell.vertices[a],
                                cell.vertices[a | (1u << axis)]);
                  AssertThrow(tetrahedron_edges.count(edge) == 0,
                              ExcMessage(
                                "a hexahedron and a tetrahedron share the "
                                "edge from " +
                                point_text(mesh.vertices[edge.first]) + " to " +
                                point_text(mesh.vertices[edge.second]) +
                                "; mesh each body with one kind of cell"));
                }

      std::vector<CellData<3>> cells;
      for (const CellData<3> &cell : mesh.cells)
        {
          const auto &v = cell.vertices;
          if (v.size() == 8)
            cells.push_back(cell);
          else
            for (unsigned int corner = 0; corner < 4; ++corner)
              {
                // The corner a and the other three b, c, d, ordered so that
                // (b - a, c - a, d - a) is right-handed: the piece's
                // Jacobian at a is a positive multiple of that frame.
                const unsigned int a = v[corner];
                unsigned int b = v[(corner + 1) % 4], c = v[(corner + 2) % 4],
                             d        = v[(corner + 3) % 4];
                const Tensor<1, 3> ab = mesh.vertices[b] - mesh.vertices[a],
                                   ac = mesh.vertices[c] - mesh.vertices[a],
                                   ad = mesh.vertices[d] - mesh.vertices[a];
                if (cross_product_3d(ab, ac) * ad < 0)
                  std::swap(c, d);
                CellData<3> piece(8);
                piece.vertices    = {a,
                                     mean({a, b}),
                                     mean({a, c}),
                                     mean({a, b, c}),
                                     mean({a, d}),
                                     mean({a, b, d}),
                                     mean({a, c, d}),
                                     mean({a, b, c, d})};
                piece.material_id = cell.material_id;
                piece.manifold_id = cell.manifold_id;
                cells.push_back(piece);
              }
        }
      mesh.cells = std::move(cells);

      std::vector<CellData<2>> faces;
      for (const CellData<2> &face : mesh.subcells.boundary_quads)
        {
          const auto &v = face.vertices;
          if (v.size() == 4)
            faces.push_back(face);
          else
            for (unsigned int corner = 0; corner < 3; ++corner)
              {
                const unsigned int a = v[corner], b = v[(corner + 1) % 3],
                                   c = v[(corner + 2) % 3];
                CellData<2> piece    = face;
                piece.vertices       = {a,
                                        mean({a, b}),
                                        mean({a, c}),
                                        mean({a, b, c})};
                faces.push_back(piece);
              }
        }
      mesh.subcells.boundary_quads = std::move(faces);

      std::vector<CellData<1>> lines;
      for (const CellData<1> &line : mesh.subcells.boundary_lines)
        {
          const auto it =
            made.find({std::min(line.vertices[0], line.vertices[1]),
                       std::max(line.vertices[0], line.vertices[1])});
          if (it == made.end())
            {
              lines.push_back(line); // an edge of a hexahedron
              continue;
            }
          for (const unsigned int end : {0u, 1u})
            {
              CellData<1> half = line;
              half.vertices    = {line.vertices[end], it->second};
              lines.push_back(half);
            }
        }
      mesh.subcells.boundary_lines = std::move(lines);

      // deal.II needs every edge to point the same way from each cell that
      // has it, as GridIn orders a file's hexahedra; meshes of tetrahedra
      // split into hexahedra can always be so ordered (Agelek, Anderson,
      // Bangerth and Barth, ACM TOMS 2017).
      GridTools::consistently_order_cells(mesh.cells);
    }
  } // namespace mesh_readers
} // namespace knee_contact
