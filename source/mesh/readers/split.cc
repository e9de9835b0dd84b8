#include <knee_contact/mesh/readers/line_reader.h>

#include <deal.II/grid/grid_tools.h>

#include <cmath>
#include <map>

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
  } // namespace mesh_readers
} // namespace knee_contact
