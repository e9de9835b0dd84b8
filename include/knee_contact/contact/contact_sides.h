#ifndef knee_contact_contact_sides_h
#define knee_contact_contact_sides_h

#include <knee_contact/base/input.h>
#include <knee_contact/contact/contact.h>
#include <knee_contact/contact/search.h>

#include <deal.II/base/geometry_info.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <array>
#include <limits>
#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The two sides of one contact interface as the contact discretisations
   * see them: the slave vertices with their averaged normals, the slave
   * faces, and the master faces (2D: segments; 3D: triangles and
   * quadrilaterals). Collected once by ContactInterfaces::make_pairs(); each
   * discretisation (node-to-segment, mortar) turns them into rows
   * a_p x <= g_p, one per slave vertex.
   */
  template <int dim>
  struct ContactSides
  {
    struct SlaveVertex
    {
      Point<dim> position;
      /**
       * Sum of the outward normals of the vertex's faces, each with the
       * face's measure (length in 2D, area in 3D) as its norm: the
       * measure-weighted average direction.
       */
      Tensor<1, dim> normal;
      /** The vertex's share of its faces: sum of measure / n_vertices. */
      double                                   length = 0;
      std::array<types::global_dof_index, dim> dofs;
      /**
       * 3D: a vertex that hangs on a refined neighbour's edge or face, the
       * slave vertices its displacement is interpolated from and their
       * weights (its hanging-node constraint); empty for a vertex of its
       * own. Its multiplier is not a free one either: the 3D rows fold its
       * share into its parents'.
       */
      std::vector<std::pair<unsigned int, double>> parents;

      Tensor<1, dim>
      unit_normal() const
      {
        return normal / normal.norm();
      }
    };

    /**
     * A face: a segment (2D), a triangle or a bilinear quadrilateral (3D),
     * its vertices in deal.II's order (a quadrilateral's 0, 1, 2, 3 are
     * (0,0), (1,0), (0,1), (1,1) of its reference square).
     */
    struct Face
    {
      static constexpr unsigned int max_vertices =
        GeometryInfo<dim>::vertices_per_face;
      unsigned int n_vertices = max_vertices;
      /** Vertex keys (into slaves for a slave face). */
      std::array<unsigned int, max_vertices> vertex_keys;
      std::array<Point<dim>, max_vertices>   vertices;
      std::array<std::array<types::global_dof_index, dim>, max_vertices> dofs;
      /** Unit outward normal (3D: at the face's centre). */
      Tensor<1, dim> normal;
      /** Length (2D) or area (3D). */
      double measure = 0;
      /** The longest distance between two of its vertices. */
      double diameter = 0;
    };

    std::map<unsigned int, SlaveVertex> slaves;
    std::vector<Face>                   slave_faces;
    std::vector<Face>                   master_faces;
    /** The shortest slave face (3D: the smallest slave face diameter). */
    double min_length = 0;
  };



  /**
   * Where the slave normal n from x meets the master side: x + s n is the
   * master face's point at parameter xi (2D: p0 + xi (p1 - p0)), the
   * closest facing master face (n_master . n < 0) along n; face is null if
   * n meets none.
   */
  template <int dim>
  struct MasterHit
  {
    const typename ContactSides<dim>::Face *face = nullptr;
    double         s = std::numeric_limits<double>::max();
    Point<dim - 1> xi;
  };

  /** The 2D master hit (also the tangent of a frictional 2D row). */
  MasterHit<2>
  master_along_normal(const ContactSides<2> &sides,
                      const Point<2>        &position,
                      const Tensor<1, 2>    &n,
                      const double           length);

  /**
   * The 3D master hit among the faces @p search finds within 2 @p h (the
   * slave's spacing) and @p maximum_gap of @p position (node-to-segment
   * rows; also the common normal of a frictional 3D row).
   */
  MasterHit<3>
  master_along_normal(const ContactSides<3>  &sides,
                      const ContactSearch<3> &search,
                      const Point<3>         &position,
                      const Tensor<1, 3>     &n,
                      const double            h,
                      const double            maximum_gap);



  /**
   * Node-to-segment rows: each slave vertex projected along its normal onto
   * the closest facing master face (the seed's node pairs when the meshes
   * match). 2D: segments; 3D: triangles and bilinear quadrilaterals (the
   * quadrilateral's point by Newton's method on its bilinear map). Rows are
   * not yet reduced by the constraints.
   */
  template <int dim>
  ContactPairs<dim>
  node_to_segment_rows(const ContactSides<dim> &sides,
                       const ContactInterface  &interface,
                       const unsigned int       interface_index,
                       const std::string       &where);

  /**
   * One slave vertex's mortar row while it is integrated: its weight
   * W_j = int psi_j (= sum_i D_ji, as sum_i phi_i = 1), M_j. by master
   * vertex (its dofs) and the weighted gap g~_j.
   */
  template <int dim>
  struct MortarSums
  {
    double                                                     weight = 0;
    std::map<std::array<types::global_dof_index, dim>, double> master;
    double                                                     gap = 0;
  };

  /**
   * The rows of the integrated sums (2D and 3D alike, mortar.cc): each
   * divided by its weight W_j and D lumped onto the diagonal; a vertex whose
   * faces the master covers for less than a quarter of its share gets no
   * row; gaps within @p tol of zero are zero.
   */
  template <int dim>
  ContactPairs<dim>
  normalised_mortar_rows(const std::map<unsigned int, MortarSums<dim>> &sums,
                         const ContactSides<dim>                       &sides,
                         const unsigned int interface_index,
                         const double       tol);

  /** The contact search over the master faces of @p sides (search.h). */
  template <int dim>
  ContactSearch<dim>
  master_face_search(const ContactSides<dim> &sides);



  /**
   * Dual mortar rows (segment-to-segment, Wohlmuth's biorthogonal
   * multiplier basis on the slave side), one per slave vertex, normalised
   * so that they read like node-to-segment rows: the slave vertex's own
   * normal displacement minus a weighted mean of the master's, against the
   * weighted gap; ContactRow::length is the row's weight, so multiplier /
   * length is the multiplier's value there, a pressure [Pa]. 2D: interval
   * clipping (mortar.cc); 3D: polygon clipping on an auxiliary plane per
   * slave face (mortar_3d.cc).
   */
  template <int dim>
  ContactPairs<dim>
  mortar_rows(const ContactSides<dim> &sides,
              const ContactInterface  &interface,
              const unsigned int       interface_index,
              const std::string       &where);
} // namespace knee_contact

#endif
