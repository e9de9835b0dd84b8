// Dual mortar contact rows on 3D faces (linear triangles, bilinear
// quadrilaterals). No library in reach segments and integrates mortar
// couplings between the faces of separate deal.II bodies (4C, MOOSE and
// Kratos do it inside their own data structures), so it is written here,
// after their pipeline (Puso and Laursen 2004; 4C's Coupling3d, MOOSE's
// MortarSegmentHelper, Kratos' ExactMortarIntegrationUtility):
//
// for each slave face S and each master face M near it (ContactSearch)
// that faces it,
//   1. the auxiliary plane of S: through S's centre, normal n_c to S there;
//   2. both faces projected orthogonally onto it;
//   3. the projected M clipped by the projected S (Sutherland-Hodgman; S is
//      convex, a cell check refuses others), slivers below 1e-12 of S's
//      area dropped (4C's MORTARINTLIM);
//   4. the clip polygon (convex) cut into a fan of triangles;
//   5. on each triangle a Gauss rule, each point mapped back to S and M
//      (the inverse of their maps seen on the plane), where
//        W_j += w psi_j,   M_jk += w psi_j phi_k^M,
//        g~_j += w psi_j (x_M - x_S) . n_j.
// Where both faces are affine (triangles, parallelograms) the integrands are
// polynomials of degree 4 in the plane and a rule of degree 5 is exact: the
// patch test holds to rounding on non-matching meshes. A general
// quadrilateral (an unstructured hexahedral mesh's face, a tetrahedron split
// into hexahedra) has a bilinear map whose inverse makes them rational, which
// no rule integrates exactly; there a collapsed Gauss rule of 16 x 16 points
// per triangle is used. Measured on the patch test with tetrahedra split into
// hexahedra (doc/3d.md): nodal error 1.0e-4, 1.4e-6, 5.6e-9, 6.8e-12,
// 4.1e-13 with 3, 5, 8, 12, 16 points per direction: rounding from 16 on.
//
// psi_j = sum_k A_jk phi_k is the dual basis of S: A = D M^-1 with
// D = diag(int phi_j) and M_jk = int phi_j phi_k, so int psi_j phi_i =
// delta_ij int phi_i. Element-wise (over all of S) it is biorthogonal only
// where S is covered whole; where the master covers S in part (the edge of
// the contact zone, a body's free edge) D and M are taken over the covered
// part instead (4C's LM_DUAL_CONSISTENT = boundary; Cichosz and Bischoff
// 2011), which keeps the rows exact for a linear field there too.
//
// The rows are then normalised and D lumped exactly as in 2D (mortar.cc).

#include <knee_contact/base/input.h>
#include <knee_contact/contact/contact_sides.h>
#include <knee_contact/contact/face_geometry.h>
#include <knee_contact/contact/search.h>

#include <deal.II/base/quadrature_lib.h>

#include <deal.II/lac/full_matrix.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace knee_contact
{
  namespace mortar_3d
  {
    using namespace face_geometry;

    using Polygon = std::vector<Point<2>>;

    double
    signed_area(const Polygon &polygon)
    {
      double twice = 0;
      for (unsigned int i = 0; i < polygon.size(); ++i)
        {
          const Point<2> &a = polygon[i];
          const Point<2> &b = polygon[(i + 1) % polygon.size()];
          twice += a[0] * b[1] - a[1] * b[0];
        }
      return 0.5 * twice;
    }

    /**
     * The face's vertices in the plane, counter-clockwise about its normal.
     */
    Polygon
    projected(const Face &face, const Plane &plane)
    {
      Polygon polygon;
      for (const unsigned int v : polygon_order(face))
        polygon.push_back(plane.coords(face.vertices[v]));
      if (signed_area(polygon) < 0)
        std::reverse(polygon.begin(), polygon.end());
      return polygon;
    }

    /**
     * Sutherland-Hodgman: @p subject clipped by the convex counter-clockwise
     * @p clipper. Points within @p tol of a clipping edge count as inside
     * (tolerance relative to the edge length, as 4C's MORTARCLIPTOL); the
     * crossing parameter is clamped to [0, 1] and points closer than tol to
     * their predecessor are merged (MOOSE's MortarSegmentHelper).
     */
    Polygon
    clip(const Polygon &subject, const Polygon &clipper, const double tol)
    {
      Polygon result = subject;
      for (unsigned int e = 0; e < clipper.size() && !result.empty(); ++e)
        {
          const Point<2>    &a      = clipper[e];
          const Tensor<1, 2> edge   = clipper[(e + 1) % clipper.size()] - a;
          const double       length = edge.norm();
          // Signed distance to the left of the edge.
          const auto side = [&](const Point<2> &p) {
            return (edge[0] * (p[1] - a[1]) - edge[1] * (p[0] - a[0])) / length;
          };
          const Polygon input = result;
          result.clear();
          for (unsigned int i = 0; i < input.size(); ++i)
            {
              const Point<2> &p  = input[i];
              const Point<2> &q  = input[(i + 1) % input.size()];
              const double    sp = side(p), sq = side(q);
              const bool      p_in = sp >= -tol, q_in = sq >= -tol;
              if (p_in)
                result.push_back(p);
              if (p_in != q_in)
                {
                  const double t = std::clamp(sp / (sp - sq), 0., 1.);
                  result.push_back(p + t * (q - p));
                }
            }
          Polygon merged;
          for (const Point<2> &p : result)
            if (merged.empty() || p.distance(merged.back()) > tol)
              merged.push_back(p);
          while (merged.size() > 1 &&
                 merged.front().distance(merged.back()) <= tol)
            merged.pop_back();
          result = merged;
        }
      return result.size() < 3 ? Polygon() : result;
    }

    /** A piece of a slave face that one master face covers. */
    struct Segment
    {
      const Face *master = nullptr;
      Polygon     polygon;
      double      area     = 0;
      double      distance = 0;
    };

    /**
     * The reference triangle's Gauss points mapped onto the triangles of a
     * fan over the convex @p polygon: (plane point, weight) pairs.
     */
    std::vector<std::pair<Point<2>, double>>
    fan_quadrature(const Polygon &polygon, const Quadrature<2> &rule)
    {
      std::vector<std::pair<Point<2>, double>> points;
      for (unsigned int i = 1; i + 1 < polygon.size(); ++i)
        {
          const Tensor<1, 2> a   = polygon[i] - polygon[0];
          const Tensor<1, 2> b   = polygon[i + 1] - polygon[0];
          const double       det = a[0] * b[1] - a[1] * b[0];
          for (unsigned int q = 0; q < rule.size(); ++q)
            points.emplace_back(polygon[0] + rule.point(q)[0] * a +
                                  rule.point(q)[1] * b,
                                rule.weight(q) * std::abs(det));
        }
      return points;
    }

    /**
     * The dual basis coefficients A = D M^-1 of the slave face over the
     * pieces @p pieces of it (all of it, or the covered part), integrated
     * on the plane.
     */
    FullMatrix<double>
    dual_coefficients(const Face                 &slave,
                      const Plane                &plane,
                      const std::vector<Polygon> &pieces,
                      const Quadrature<2>        &rule)
    {
      const unsigned int n = slave.n_vertices;
      FullMatrix<double> mass(n, n), lumped(n, n);
      for (const Polygon &piece : pieces)
        for (const auto &[x, w] : fan_quadrature(piece, rule))
          {
            Point<2> xi;
            if (!inverse_on_plane(slave, plane, x, xi))
              continue;
            const std::array<double, 4> phi = shape_values(slave, xi);
            for (unsigned int j = 0; j < n; ++j)
              {
                lumped(j, j) += w * phi[j];
                for (unsigned int k = 0; k < n; ++k)
                  mass(j, k) += w * phi[j] * phi[k];
              }
          }
      FullMatrix<double> inverse(n, n), a(n, n);
      inverse.invert(mass);
      lumped.mmult(a, inverse);
      return a;
    }

  } // namespace mortar_3d



  template <>
  ContactPairs<3>
  mortar_rows(const ContactSides<3>  &sides,
              const ContactInterface &interface,
              const unsigned int      interface_index,
              const std::string      &where)
  {
    namespace m3 = mortar_3d;
    using face_geometry::Face;
    using face_geometry::Plane;
    const Quadrature<2> affine_rule  = QGaussSimplex<2>(3); // degree 5
    const Quadrature<2> general_rule = QDuffy(16, 1.);
    const double        tol          = 1e-8 * sides.min_length;

    const ContactSearch<3> search = master_face_search(sides);

    std::map<unsigned int, MortarSums<3>> rows;
    for (const Face &slave : sides.slave_faces)
      {
        const double L = slave.diameter;
        // As in 2D: an overlap up to 2 % of the face's size is a chord
        // error of two meshes of one curved surface (accepted, pushed apart
        // by the conditions); more is a real overlap of the bodies.
        const double      overlap_allowed = std::max(tol, 0.02 * L);
        const Plane       plane         = face_geometry::auxiliary_plane(slave);
        const m3::Polygon slave_polygon = m3::projected(slave, plane);
        const double      slave_area    = m3::signed_area(slave_polygon);
        const double      clip_tol      = 1e-8 * L;

        // 1-3: the pieces of S each facing master face covers, with the
        // master's distance along n_c at the piece's centroid.
        std::vector<m3::Segment>    segments;
        const std::vector<Point<3>> corners(slave.vertices.begin(),
                                            slave.vertices.begin() +
                                              slave.n_vertices);
        for (const unsigned int m : search.near(
               BoundingBox<3>(corners), plane.centre, L, interface.maximum_gap))
          {
            const Face &master = sides.master_faces[m];
            if (master.normal * plane.normal >= 0)
              continue;
            m3::Segment segment;
            segment.master = &master;
            segment.polygon =
              m3::clip(m3::projected(master, plane), slave_polygon, clip_tol);
            segment.area = m3::signed_area(segment.polygon);
            if (segment.polygon.empty() || segment.area < 1e-12 * slave_area)
              continue;
            Point<2> centroid;
            for (const Point<2> &p : segment.polygon)
              centroid += p / double(segment.polygon.size());
            Point<2> xi, eta;
            if (!face_geometry::inverse_on_plane(slave, plane, centroid, xi) ||
                !face_geometry::inverse_on_plane(master, plane, centroid, eta))
              continue;
            const double s = (face_geometry::map(master, eta) -
                              face_geometry::map(slave, xi)) *
                             plane.normal;
            if (s < -L ||
                (interface.maximum_gap > 0 && s > interface.maximum_gap))
              continue;
            segment.distance = std::abs(s);
            segments.push_back(std::move(segment));
          }
        // One layer of the master side: where two master faces cover the
        // same part of S (a master surface that folds over, or two layers
        // of it), the nearer one, as in 2D.
        std::sort(segments.begin(),
                  segments.end(),
                  [](const m3::Segment &a, const m3::Segment &b) {
                    return a.distance < b.distance;
                  });
        std::vector<m3::Segment> kept;
        double                   covered = 0;
        for (m3::Segment &segment : segments)
          {
            bool overlaps = false;
            for (const m3::Segment &other : kept)
              {
                const m3::Polygon common =
                  m3::clip(segment.polygon, other.polygon, clip_tol);
                if (!common.empty() &&
                    m3::signed_area(common) > 1e-6 * segment.area)
                  overlaps = true;
              }
            if (!overlaps)
              {
                covered += segment.area;
                kept.push_back(std::move(segment));
              }
          }
        if (kept.empty())
          continue;

        // The dual basis: element-wise where S is covered whole, over the
        // covered part where it is not.
        std::vector<m3::Polygon> pieces;
        if (covered < (1 - 1e-10) * slave_area)
          for (const m3::Segment &segment : kept)
            pieces.push_back(segment.polygon);
        else
          pieces.push_back(slave_polygon);
        const FullMatrix<double> A =
          m3::dual_coefficients(slave,
                                plane,
                                pieces,
                                face_geometry::is_affine(slave) ? affine_rule
                                                                : general_rule);

        // 5: integrate.
        for (const m3::Segment &segment : kept)
          {
            const Face &master = *segment.master;
            // Initial overlap: the gap along n_c at the piece's corners.
            for (const Point<2> &corner : segment.polygon)
              {
                Point<2> xi, eta;
                if (!face_geometry::inverse_on_plane(
                      slave, plane, corner, xi) ||
                    !face_geometry::inverse_on_plane(
                      master, plane, corner, eta))
                  continue;
                const Point<3> xs = face_geometry::map(slave, xi);
                const double   gap =
                  (face_geometry::map(master, eta) - xs) * plane.normal;
                AssertThrow(gap >= -overlap_allowed,
                            ExcMessage(
                              where + "the slave side at " + point_text(xs) +
                              " penetrates the master side by " +
                              input::format(-gap) +
                              " m (more than 2 % of the face size, the "
                              "chord error accepted); initial overlap is "
                              "not supported"));
              }
            const Quadrature<2> &rule = face_geometry::is_affine(slave) &&
                                            face_geometry::is_affine(master)
                                          ? affine_rule
                                          : general_rule;
            for (const auto &[x, w] : m3::fan_quadrature(segment.polygon, rule))
              {
                Point<2> xi, eta;
                if (!face_geometry::inverse_on_plane(slave, plane, x, xi) ||
                    !face_geometry::inverse_on_plane(master, plane, x, eta))
                  continue;
                const std::array<double, 4> phi =
                  face_geometry::shape_values(slave, xi);
                const std::array<double, 4> phi_master =
                  face_geometry::shape_values(master, eta);
                const Tensor<1, 3> x_jump = face_geometry::map(master, eta) -
                                            face_geometry::map(slave, xi);
                for (unsigned int j = 0; j < slave.n_vertices; ++j)
                  {
                    double psi = 0;
                    for (unsigned int k = 0; k < slave.n_vertices; ++k)
                      psi += A(j, k) * phi[k];
                    const unsigned int key = slave.vertex_keys[j];
                    MortarSums<3>     &row = rows[key];
                    row.weight += w * psi;
                    for (unsigned int k = 0; k < master.n_vertices; ++k)
                      row.master[master.dofs[k]] += w * psi * phi_master[k];
                    row.gap +=
                      w * psi * (x_jump * sides.slaves.at(key).unit_normal());
                  }
              }
          }
      }

    // A hanging slave vertex's multiplier is its parents' (the multiplier
    // space is the constrained trace space): its sums go to its parents with
    // the weights of its constraint, u_h = sum_q c_q u_q, and it gets no row.
    for (const auto &[key, vertex] : sides.slaves)
      if (!vertex.parents.empty())
        {
          const auto hanging = rows.find(key);
          if (hanging == rows.end())
            continue;
          const MortarSums<3> sums = hanging->second;
          rows.erase(hanging);
          for (const auto &[parent, c] : vertex.parents)
            {
              MortarSums<3> &row = rows[parent];
              row.weight += c * sums.weight;
              row.gap += c * sums.gap;
              for (const auto &[dofs, M] : sums.master)
                row.master[dofs] += c * M;
            }
        }

    // Normalised and D lumped as in 2D.
    return normalised_mortar_rows<3>(rows, sides, interface_index, tol);
  }
} // namespace knee_contact
