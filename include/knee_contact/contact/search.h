#ifndef knee_contact_contact_search_h
#define knee_contact_contact_search_h

#include <deal.II/base/bounding_box.h>
#include <deal.II/base/point.h>

#include <deal.II/numerics/rtree.h>

#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The one contact search: the bounding boxes of a side's faces in deal.II's
   * RTree (boost.geometry, packed), asked for the faces near a box or a
   * point. Serves the 3D discretisations (mortar's candidate master faces of
   * a slave face, node-to-segment's of a slave vertex) and the refinement's
   * partner marking; O(log n) a query where an all-pairs loop is quadratic
   * at 3D face counts (1e4-1e5).
   */
  template <int dim>
  class ContactSearch
  {
  public:
    /** Index the boxes; box i answers as i. */
    explicit ContactSearch(const std::vector<BoundingBox<dim>> &boxes);

    /** The indices of the boxes that meet @p box, ascending. */
    std::vector<unsigned int>
    intersecting(const BoundingBox<dim> &box) const;

    /**
     * The distance from @p point to the nearest box (0 inside one);
     * infinite if there are none.
     */
    double
    distance_to_nearest(const Point<dim> &point) const;

    /**
     * The indices of the boxes that meet @p box grown by the distance from
     * @p centre to the nearest box plus @p margin on every side: the faces
     * as near as the nearest one, and farther by at most the margin. With a
     * @p limit > 0 the growth is at most limit + margin.
     */
    std::vector<unsigned int>
    near(const BoundingBox<dim> &box,
         const Point<dim>       &centre,
         const double            margin,
         const double            limit) const;

  private:
    using Tree = RTree<std::pair<BoundingBox<dim>, unsigned int>>;
    Tree tree;
  };
} // namespace knee_contact

#endif
