#include <knee_contact/mesh/mesh.h>

#include <deal.II/base/tensor.h>

#include <array>
#include <map>
#include <numeric>
#include <string>

namespace knee_contact
{
  template <int dim>
  void
  check_cells(const Triangulation<dim> &triangulation)
  {
    // The Jacobian of a bilinear quadrilateral is positive everywhere iff
    // the cross products of the edges at all four corners are (deal.II's
    // vertex order 0 1 3 2 runs counter-clockwise); a triangle's at any.
    // A trilinear hexahedron needs the triple product of its three edges
    // positive at all eight corners (necessary; sufficient for the
    // parallelepipeds and mildly distorted cells meshers make), a
    // tetrahedron at one. Checked on every mesh the program solves on:
    // refinement on a circle that does not fit the vertices can fold cells.
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int n  = cell->n_vertices();
        bool               ok = true;
        if constexpr (dim == 2)
          {
            // A triangle's vertices 0 1 2 run counter-clockwise too.
            const std::array<unsigned int, 4> ring =
              n == 3 ? std::array<unsigned int, 4>{{0, 1, 2}}
                     : std::array<unsigned int, 4>{{0, 1, 3, 2}};
            for (unsigned int k = 0; k < n; ++k)
              {
                const Tensor<1, 2> a =
                  cell->vertex(ring[(k + 1) % n]) - cell->vertex(ring[k]);
                const Tensor<1, 2> b =
                  cell->vertex(ring[(k + n - 1) % n]) - cell->vertex(ring[k]);
                ok &= a[0] * b[1] - a[1] * b[0] > 1e-12 * a.norm() * b.norm();
              }
          }
        else
          // Corner v = i + 2j + 4k of a hexahedron has its neighbours along
          // the three directions at v ^ 1, v ^ 2, v ^ 4, a right-handed
          // triple if i + j + k is even; a tetrahedron's corner 0 has 1 2 3.
          for (unsigned int v = 0; v < (n == 4 ? 1u : 8u); ++v)
            {
              const std::array<unsigned int, 3> next =
                n == 4 ? std::array<unsigned int, 3>{{1, 2, 3}}
                       : std::array<unsigned int, 3>{{v ^ 1u, v ^ 2u, v ^ 4u}};
              const Tensor<1, dim> a = cell->vertex(next[0]) - cell->vertex(v),
                                   b = cell->vertex(next[1]) - cell->vertex(v),
                                   c = cell->vertex(next[2]) - cell->vertex(v);
              const double sign =
                (((v & 1) + ((v >> 1) & 1) + ((v >> 2) & 1)) % 2 == 0) ? 1.
                                                                       : -1.;
              ok &= sign * (cross_product_3d(a, b) * c) >
                    1e-12 * a.norm() * b.norm() * c.norm();
            }
        if (!ok)
          {
            std::string centre;
            for (unsigned int d = 0; d < dim; ++d)
              centre +=
                (d == 0 ? "" : ", ") + std::to_string(cell->center()[d]);
            AssertThrow(false,
                        ExcMessage("Mesh: cell at (" + centre +
                                   ") is inverted, degenerate or not convex" +
                                   (cell->level() > 0
                                      ? " after refinement (level " +
                                          std::to_string(cell->level()) + ")"
                                      : std::string())));
          }
      }
  }



  template <int dim>
  std::vector<unsigned int>
  compute_body_ids(const Triangulation<dim> &triangulation,
                   unsigned int             &n_bodies)
  {
    // Union-find over vertices: cells that share a vertex are one body.
    std::vector<unsigned int> parent(triangulation.n_vertices());
    std::iota(parent.begin(), parent.end(), 0);
    const auto find = [&parent](unsigned int v) {
      while (parent[v] != v)
        v = parent[v] = parent[parent[v]];
      return v;
    };
    for (const auto &cell : triangulation.active_cell_iterators())
      for (const unsigned int v : cell->vertex_indices())
        parent[find(cell->vertex_index(v))] = find(cell->vertex_index(0));

    std::vector<unsigned int>            body(triangulation.n_active_cells());
    std::map<unsigned int, unsigned int> number;
    for (const auto &cell : triangulation.active_cell_iterators())
      {
        const unsigned int root = find(cell->vertex_index(0));
        const auto         it   = number.emplace(root, number.size()).first;
        body[cell->active_cell_index()] = it->second;
      }
    n_bodies = number.size();
    return body;
  }



  template void
  check_cells(const Triangulation<2> &);
  template void
  check_cells(const Triangulation<3> &);
  template std::vector<unsigned int>
  compute_body_ids(const Triangulation<2> &, unsigned int &);
  template std::vector<unsigned int>
  compute_body_ids(const Triangulation<3> &, unsigned int &);
} // namespace knee_contact
