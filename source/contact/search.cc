#include <knee_contact/contact/contact_sides.h>
#include <knee_contact/contact/search.h>

#include <boost/geometry/index/rtree.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>

namespace knee_contact
{
  template <int dim>
  ContactSearch<dim>::ContactSearch(const std::vector<BoundingBox<dim>> &boxes)
  {
    std::vector<std::pair<BoundingBox<dim>, unsigned int>> entries;
    entries.reserve(boxes.size());
    for (unsigned int i = 0; i < boxes.size(); ++i)
      entries.emplace_back(boxes[i], i);
    tree = pack_rtree(entries);
  }



  template <int dim>
  std::vector<unsigned int>
  ContactSearch<dim>::intersecting(const BoundingBox<dim> &box) const
  {
    std::vector<std::pair<BoundingBox<dim>, unsigned int>> hits;
    tree.query(boost::geometry::index::intersects(box),
               std::back_inserter(hits));
    std::vector<unsigned int> indices;
    indices.reserve(hits.size());
    for (const auto &hit : hits)
      indices.push_back(hit.second);
    std::sort(indices.begin(), indices.end());
    return indices;
  }



  template <int dim>
  double
  ContactSearch<dim>::distance_to_nearest(const Point<dim> &point) const
  {
    std::vector<std::pair<BoundingBox<dim>, unsigned int>> hits;
    tree.query(boost::geometry::index::nearest(point, 1),
               std::back_inserter(hits));
    if (hits.empty())
      return std::numeric_limits<double>::infinity();
    // Distance from the point to the box (9.4's BoundingBox has none): per
    // coordinate, how far it lies outside the box's interval.
    double square = 0;
    for (unsigned int d = 0; d < dim; ++d)
      {
        const auto  &box = hits.front().first.get_boundary_points();
        const double outside =
          std::max({box.first[d] - point[d], point[d] - box.second[d], 0.});
        square += outside * outside;
      }
    return std::sqrt(square);
  }



  template <int dim>
  std::vector<unsigned int>
  ContactSearch<dim>::near(const BoundingBox<dim> &box,
                           const Point<dim>       &centre,
                           const double            margin,
                           const double            limit) const
  {
    double grow = distance_to_nearest(centre);
    if (!std::isfinite(grow))
      return {};
    if (limit > 0)
      grow = std::min(grow, limit);
    BoundingBox<dim> grown = box;
    grown.extend(grow + margin);
    return intersecting(grown);
  }



  template <int dim>
  ContactSearch<dim>
  master_face_search(const ContactSides<dim> &sides)
  {
    std::vector<BoundingBox<dim>> boxes;
    for (const auto &face : sides.master_faces)
      boxes.emplace_back(
        std::vector<Point<dim>>(face.vertices.begin(),
                                face.vertices.begin() + face.n_vertices));
    return ContactSearch<dim>(boxes);
  }



  template class ContactSearch<2>;
  template ContactSearch<2>
  master_face_search(const ContactSides<2> &);
  template ContactSearch<3>
  master_face_search(const ContactSides<3> &);
  template class ContactSearch<3>;
} // namespace knee_contact
