#ifndef knee_contact_face_geometry_h
#define knee_contact_face_geometry_h

#include <knee_contact/contact/contact_sides.h>

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <array>
#include <cmath>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The geometry of a 3D contact face (a linear triangle or a bilinear
   * quadrilateral, ContactSides<3>::Face) that the 3D discretisations
   * share: its shape functions phi_a(xi), its map F(xi) = sum_a phi_a(xi)
   * x_a, the inverse of that map seen on a plane, and the auxiliary plane of
   * a slave face. Written here: deal.II maps cells, not a contact face seen
   * from another body's face.
   */
  namespace face_geometry
  {
    using Face = ContactSides<3>::Face;

    /** phi_a(xi) (a triangle's first entries, then zeros). */
    inline std::array<double, 4>
    shape_values(const Face &face, const Point<2> &xi)
    {
      if (face.n_vertices == 3)
        return {{1 - xi[0] - xi[1], xi[0], xi[1], 0}};
      return {{(1 - xi[0]) * (1 - xi[1]),
               xi[0] * (1 - xi[1]),
               (1 - xi[0]) * xi[1],
               xi[0] * xi[1]}};
    }

    /** F(xi). */
    inline Point<3>
    map(const Face &face, const Point<2> &xi)
    {
      const std::array<double, 4> phi = shape_values(face, xi);
      Point<3>                    x;
      for (unsigned int a = 0; a < face.n_vertices; ++a)
        x += phi[a] * face.vertices[a];
      return x;
    }

    /** The derivatives dF/dxi_0 and dF/dxi_1. */
    inline std::array<Tensor<1, 3>, 2>
    tangents(const Face &face, const Point<2> &xi)
    {
      const auto &x = face.vertices;
      if (face.n_vertices == 3)
        return {{x[1] - x[0], x[2] - x[0]}};
      return {{(1 - xi[1]) * (x[1] - x[0]) + xi[1] * (x[3] - x[2]),
               (1 - xi[0]) * (x[2] - x[0]) + xi[0] * (x[3] - x[1])}};
    }

    /** The face's vertex order around its boundary (0 1 2, or 0 1 3 2). */
    inline std::vector<unsigned int>
    polygon_order(const Face &face)
    {
      if (face.n_vertices == 3)
        return {0, 1, 2};
      return {0, 1, 3, 2};
    }

    /**
     * Whether the face's map is affine: a triangle, or a parallelogram
     * (x0 + x3 = x1 + x2 up to 1e-12 of its size). Only then are the
     * face's shape functions polynomials of the position in a plane.
     */
    inline bool
    is_affine(const Face &face)
    {
      if (face.n_vertices == 3)
        return true;
      const auto  &x    = face.vertices;
      const double size = (x[3] - x[0]).norm() + (x[2] - x[1]).norm();
      return (x[0] + (x[3] - x[1]) - x[2]).norm() <= 1e-12 * size;
    }

    /** The reference point of the face's centre. */
    inline Point<2>
    centre_xi(const Face &face)
    {
      return face.n_vertices == 3 ? Point<2>(1. / 3, 1. / 3)
                                  : Point<2>(0.5, 0.5);
    }

    /**
     * Whether xi lies in the reference triangle or square, up to @p tol.
     */
    inline bool
    inside(const Face &face, const Point<2> &xi, const double tol)
    {
      if (xi[0] < -tol || xi[1] < -tol)
        return false;
      if (face.n_vertices == 3)
        return xi[0] + xi[1] <= 1 + tol;
      return xi[0] <= 1 + tol && xi[1] <= 1 + tol;
    }

    /**
     * An auxiliary plane: a point, its unit normal and two unit tangents
     * (t1, t2, normal right-handed); coords() are a point's coordinates in
     * the plane after the orthogonal projection onto it.
     */
    struct Plane
    {
      Point<3>     centre;
      Tensor<1, 3> normal, t1, t2;

      Point<2>
      coords(const Point<3> &x) const
      {
        const Tensor<1, 3> r = x - centre;
        return Point<2>(r * t1, r * t2);
      }
    };

    /**
     * The auxiliary plane of a face (Puso and Laursen; 4C's Coupling3d):
     * through F at the face's centre, normal to the face there, t1 along
     * the first edge.
     */
    inline Plane
    auxiliary_plane(const Face &face)
    {
      Plane                             plane;
      const Point<2>                    xi = centre_xi(face);
      const std::array<Tensor<1, 3>, 2> d  = tangents(face, xi);
      plane.centre                         = map(face, xi);
      plane.normal                         = face.normal;
      plane.t1 = d[0] - (d[0] * plane.normal) * plane.normal;
      plane.t1 /= plane.t1.norm();
      plane.t2 = cross_product_3d(plane.normal, plane.t1);
      return plane;
    }

    /**
     * The reference point xi whose image F(xi), projected along the
     * plane's normal, is the plane point @p x: linear for a triangle,
     * Newton's method on the bilinear map for a quadrilateral (one step
     * on a parallelogram). False if Newton does not converge (a face seen
     * edge-on).
     */
    inline bool
    inverse_on_plane(const Face     &face,
                     const Plane    &plane,
                     const Point<2> &x,
                     Point<2>       &xi)
    {
      std::array<Point<2>, 4> p;
      for (unsigned int a = 0; a < face.n_vertices; ++a)
        p[a] = plane.coords(face.vertices[a]);
      xi                     = centre_xi(face);
      double       last_step = 1;
      const double scale     = (p[1] - p[0]).norm() + (p[2] - p[0]).norm();
      for (unsigned int iteration = 0; iteration < 30; ++iteration)
        {
          Tensor<1, 2> a, b;
          Point<2>     f;
          if (face.n_vertices == 3)
            {
              a = p[1] - p[0];
              b = p[2] - p[0];
              f = p[0] + xi[0] * a + xi[1] * b;
            }
          else
            {
              a = (1 - xi[1]) * (p[1] - p[0]) + xi[1] * (p[3] - p[2]);
              b = (1 - xi[0]) * (p[2] - p[0]) + xi[0] * (p[3] - p[1]);
              const std::array<double, 4> phi = shape_values(face, xi);
              f                               = Point<2>();
              for (unsigned int v = 0; v < 4; ++v)
                f += phi[v] * p[v];
            }
          const Tensor<1, 2> r   = x - f;
          const double       det = a[0] * b[1] - a[1] * b[0];
          if (std::abs(det) < 1e-14 * scale * scale)
            return false;
          const Tensor<1, 2> step({(r[0] * b[1] - r[1] * b[0]) / det,
                                   (a[0] * r[1] - a[1] * r[0]) / det});
          xi += step;
          last_step = step.norm();
          if (face.n_vertices == 3 || last_step < 1e-13)
            return true;
        }
      return last_step < 1e-10;
    }
  } // namespace face_geometry
} // namespace knee_contact

#endif
