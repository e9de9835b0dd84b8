// Node-to-segment and node-to-node rows: each slave vertex x with its
// averaged unit normal n paired with the point y = x + s n where n meets the
// closest facing master face,
//   n . (u^k(x) - u^l(y)) <= g,   g = n . (y - x) = s,
// u^l(y) interpolated by the master face's shape functions at y (the seed's
// node pairs when y is a master vertex). No library projects a vertex of one
// deal.II body onto the faces of another, so it is written here: 2D on
// segments, 3D on triangles (linear) and bilinear quadrilaterals (Newton's
// method on x + s n = F(xi)).

#include <knee_contact/contact/contact_sides.h>
#include <knee_contact/contact/face_geometry.h>
#include <knee_contact/contact/search.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace knee_contact
{
  MasterHit<2>
  master_along_normal(const ContactSides<2> &sides,
                      const Point<2>        &position,
                      const Tensor<1, 2>    &n,
                      const double           length)
  {
    MasterHit<2> hit;
    for (const ContactSides<2>::Face &m : sides.master_faces)
      {
        if (m.normal * n >= 0)
          continue;
        const Tensor<1, 2> t   = m.vertices[1] - m.vertices[0];
        const Tensor<1, 2> r   = m.vertices[0] - position;
        const double       det = -n[0] * t[1] + n[1] * t[0];
        if (std::abs(det) < 1e-12 * t.norm())
          continue;
        const double s  = (-r[0] * t[1] + r[1] * t[0]) / det;
        const double xi = (n[0] * r[1] - n[1] * r[0]) / det;
        if (xi < -1e-10 || xi > 1 + 1e-10 || s < -2 * length)
          continue;
        if (std::abs(s) < std::abs(hit.s))
          {
            hit.s     = s;
            hit.xi[0] = std::clamp(xi, 0., 1.);
            hit.face  = &m;
          }
      }
    return hit;
  }



  template <>
  ContactPairs<2>
  node_to_segment_rows(const ContactSides<2>  &sides,
                       const ContactInterface &interface,
                       const unsigned int      interface_index,
                       const std::string      &where)
  {
    ContactPairs<2> pairs;
    for (const auto &[vertex, slave] : sides.slaves)
      {
        const Tensor<1, 2> n   = slave.unit_normal();
        const double       tol = 1e-8 * sides.min_length;
        const MasterHit<2> hit =
          master_along_normal(sides, slave.position, n, slave.length);
        double                       best_s  = hit.s;
        double                       best_xi = hit.xi[0];
        const ContactSides<2>::Face *best    = hit.face;
        if (best != nullptr && std::abs(best_s) <= tol)
          best_s = 0;
        if (best != nullptr && (best_xi < 1e-8 || best_xi > 1 - 1e-8) &&
            best_s == 0)
          best_xi = std::round(best_xi);
        if (interface.pairing == Pairing::node_to_node)
          AssertThrow(best != nullptr && best_s == 0 &&
                        (best_xi == 0 || best_xi == 1),
                      ExcMessage(where +
                                 "node-to-node pairing: slave "
                                 "vertex at (" +
                                 std::to_string(slave.position[0]) + ", " +
                                 std::to_string(slave.position[1]) +
                                 ") has no coincident master vertex"));
        if (best == nullptr ||
            (interface.maximum_gap > 0 && best_s > interface.maximum_gap))
          continue;
        AssertThrow(best_s >= -tol,
                    ExcMessage(where + "slave vertex at (" +
                               std::to_string(slave.position[0]) + ", " +
                               std::to_string(slave.position[1]) +
                               ") penetrates the master side by " +
                               std::to_string(-best_s) +
                               " m; initial overlap is not supported"));

        ContactRow pair;
        pair.interface = interface_index;
        pair.gap       = best_s;
        pair.length    = slave.length;
        for (unsigned int d = 0; d < 2; ++d)
          pair.row.emplace_back(slave.dofs[d], n[d]);
        for (unsigned int v = 0; v < 2; ++v)
          {
            const double weight = v == 0 ? 1 - best_xi : best_xi;
            if (weight != 0)
              for (unsigned int d = 0; d < 2; ++d)
                pair.row.emplace_back(best->dofs[v][d], -weight * n[d]);
          }
        pairs.push_back(std::move(pair), {slave.position, n, slave.dofs, {}});
      }
    return pairs;
  }



  namespace node_to_segment_3d
  {
    using face_geometry::Face;

    /**
     * x + s n = F(xi) on one master face: (xi, s) by Newton's method
     * (exact in one step on a triangle or a parallelogram); false if the
     * line runs along the face or Newton does not converge.
     */
    bool
    intersect(const Face         &face,
              const Point<3>     &x,
              const Tensor<1, 3> &n,
              Point<2>           &xi,
              double             &s)
    {
      xi = face_geometry::centre_xi(face);
      s  = (face_geometry::map(face, xi) - x) * n;
      for (unsigned int iteration = 0; iteration < 30; ++iteration)
        {
          const auto         d = face_geometry::tangents(face, xi);
          const Tensor<1, 3> r = face_geometry::map(face, xi) - (x + s * n);
          Tensor<2, 3>       J;
          for (unsigned int i = 0; i < 3; ++i)
            {
              J[i][0] = d[0][i];
              J[i][1] = d[1][i];
              J[i][2] = -n[i];
            }
          const double det = determinant(J);
          if (std::abs(det) < 1e-12 * d[0].norm() * d[1].norm())
            return false;
          const Tensor<1, 3> step = invert(J) * r;
          xi[0] -= step[0];
          xi[1] -= step[1];
          s -= step[2];
          if (std::abs(step[0]) + std::abs(step[1]) < 1e-13 &&
              std::abs(step[2]) < 1e-13 * face.diameter)
            return true;
        }
      return false;
    }
  } // namespace node_to_segment_3d



  MasterHit<3>
  master_along_normal(const ContactSides<3>  &sides,
                      const ContactSearch<3> &search,
                      const Point<3>         &position,
                      const Tensor<1, 3>     &n,
                      const double            h,
                      const double            maximum_gap)
  {
    using Face = ContactSides<3>::Face;
    MasterHit<3> hit;
    for (const unsigned int m :
         search.near(BoundingBox<3>(std::vector<Point<3>>{position}),
                     position,
                     2 * h,
                     maximum_gap))
      {
        const Face &master = sides.master_faces[m];
        if (master.normal * n >= 0)
          continue;
        Point<2> xi;
        double   s = 0;
        if (!node_to_segment_3d::intersect(master, position, n, xi, s) ||
            !face_geometry::inside(master, xi, 1e-10) || s < -2 * h)
          continue;
        if (std::abs(s) < std::abs(hit.s))
          {
            hit.s    = s;
            hit.xi   = xi;
            hit.face = &master;
          }
      }
    return hit;
  }



  template <>
  ContactPairs<3>
  node_to_segment_rows(const ContactSides<3>  &sides,
                       const ContactInterface &interface,
                       const unsigned int      interface_index,
                       const std::string      &where)
  {
    using Face                    = ContactSides<3>::Face;
    const ContactSearch<3> search = master_face_search(sides);
    const double           tol    = 1e-8 * sides.min_length;

    ContactPairs<3> pairs;
    for (const auto &[vertex, slave] : sides.slaves)
      {
        // A hanging slave vertex follows its parents, whose rows hold it.
        if (!slave.parents.empty())
          continue;
        const Tensor<1, 3> n = slave.unit_normal();
        // The vertex's spacing: the side of a square of its area share.
        const double h   = std::sqrt(slave.length);
        MasterHit<3> hit = master_along_normal(
          sides, search, slave.position, n, h, interface.maximum_gap);
        const auto no_coincident_vertex = [&]() {
          return ExcMessage(where + "node-to-node pairing: slave vertex at " +
                            point_text(slave.position) +
                            " has no coincident master vertex");
        };
        if (hit.face == nullptr)
          {
            AssertThrow(interface.pairing != Pairing::node_to_node,
                        no_coincident_vertex());
            continue;
          }
        const Face &face = *hit.face;
        // Onto the face: a point found just outside it (within 1e-10) on
        // its edge.
        for (unsigned int d = 0; d < 2; ++d)
          hit.xi[d] = std::clamp(hit.xi[d], 0., 1.);
        if (face.n_vertices == 3 && hit.xi[0] + hit.xi[1] > 1)
          hit.xi /= hit.xi[0] + hit.xi[1];
        if (std::abs(hit.s) <= tol)
          hit.s = 0;
        std::array<double, 4> phi = face_geometry::shape_values(face, hit.xi);
        if (hit.s == 0)
          for (double &value : phi)
            if (value < 1e-8 || value > 1 - 1e-8)
              value = std::round(value);
        if (interface.pairing == Pairing::node_to_node)
          AssertThrow(hit.s == 0 && std::count(phi.begin(), phi.end(), 1.) == 1,
                      no_coincident_vertex());
        if (interface.maximum_gap > 0 && hit.s > interface.maximum_gap)
          continue;
        AssertThrow(
          hit.s >= -tol,
          ExcMessage(where + "slave vertex at " + point_text(slave.position) +
                     " penetrates the master side by " + input::format(-hit.s) +
                     " m; initial overlap is not supported"));

        ContactRow pair;
        pair.interface = interface_index;
        pair.gap       = hit.s;
        pair.length    = slave.length;
        for (unsigned int d = 0; d < 3; ++d)
          pair.row.emplace_back(slave.dofs[d], n[d]);
        for (unsigned int v = 0; v < face.n_vertices; ++v)
          if (phi[v] != 0)
            for (unsigned int d = 0; d < 3; ++d)
              pair.row.emplace_back(face.dofs[v][d], -phi[v] * n[d]);
        pairs.push_back(std::move(pair), {slave.position, n, slave.dofs, {}});
      }
    return pairs;
  }
} // namespace knee_contact
