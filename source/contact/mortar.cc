// Dual mortar contact rows (segment-to-segment). No library in reach builds
// mortar integrals for deal.II's contact of separate bodies (deal.II has no
// contact; Kratos, MOOSE, CalculiX do it inside their own data structures),
// so they are written here for 2D linear faces.
//
// The multiplier lives on the slave side in the dual basis of the linear
// trace space: on a slave face with shape functions phi_a = 1 - xi,
// phi_b = xi, psi_a = 3 phi_a - 1, psi_b = 3 phi_b - 1, so that
// int psi_j phi_i = delta_ij int phi_i (biorthogonal) and psi_a + psi_b = 1.
// For a slave vertex j with averaged unit normal n_j, the weighted
// condition is
//   sum_i D_ji n_j.u_i - sum_k M_jk n_j.u_k <= g~_j,
//   D_ji = int psi_j phi_i,  M_jk = int psi_j phi_k^master,
//   g~_j = int psi_j (x_master - x_slave).n_j,
// integrated over the pieces of the slave faces that the master faces'
// orthogonal projections cut (on each piece every integrand is a product
// of two affine functions, so 2-point Gauss is exact: no quadrature across
// kinks). Where a slave face is fully covered D is diagonal (elsewhere it
// is lumped, see below). Each row is
// divided by its weight W_j = sum_i D_ji = int psi_j, so that it reads like
// a node-to-segment row (own normal displacement minus a weighted mean of
// the master's) and the multiplier divided by ContactRow::length = W_j is
// the coefficient of the pressure in the dual basis: a constant pressure p
// gives exactly p at every vertex.

#include <knee_contact/contact/contact_sides.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace knee_contact
{
  namespace
  {
    // The parts of [lo, hi] not covered by the intervals in taken.
    std::vector<std::pair<double, double>>
    uncovered(const double                                  lo,
              const double                                  hi,
              const std::vector<std::pair<double, double>> &taken)
    {
      std::vector<std::pair<double, double>> pieces = {{lo, hi}};
      for (const auto &[t0, t1] : taken)
        {
          std::vector<std::pair<double, double>> next;
          for (const auto &[p0, p1] : pieces)
            {
              if (t1 <= p0 || t0 >= p1)
                next.emplace_back(p0, p1);
              else
                {
                  if (t0 > p0)
                    next.emplace_back(p0, t0);
                  if (t1 < p1)
                    next.emplace_back(t1, p1);
                }
            }
          pieces = next;
        }
      return pieces;
    }
  } // namespace



  template <>
  ContactPairs<2>
  mortar_rows(const ContactSides<2>  &sides,
              const ContactInterface &interface,
              const unsigned int      interface_index,
              const std::string      &where)
  {
    std::map<unsigned int, MortarSums<2>> rows;
    const double                          g   = 1 / std::sqrt(3.);
    const double                          tol = 1e-8 * sides.min_length;

    for (const ContactSides<2>::Face &slave : sides.slave_faces)
      {
        const Point<2>    &xa = slave.vertices[0];
        const Tensor<1, 2> e  = slave.vertices[1] - xa;
        const double       L  = e.norm();
        // Two sides of one circle meshed independently overlap by up to the
        // chord's sagitta L^2 / (8 R): accepted (as an interference fit the
        // contact conditions push apart) up to 2 % of the face length, an
        // arc of 9 degrees per face; more is a real overlap of the bodies.
        const double overlap_allowed = std::max(tol, 0.02 * L);
        // The master faces facing this slave face, with the slave
        // parameter interval their projection covers, nearest first.
        struct Candidate
        {
          double                       lo, hi, xi_c, xi_d, distance;
          const ContactSides<2>::Face *master;

          // The point of the master face that projects onto slave
          // parameter xi.
          Point<2>
          master_point(const double xi) const
          {
            const double eta = (xi - xi_c) / (xi_d - xi_c);
            return master->vertices[0] +
                   eta * (master->vertices[1] - master->vertices[0]);
          }
        };
        std::vector<Candidate> candidates;
        for (const ContactSides<2>::Face &master : sides.master_faces)
          {
            if (master.normal * slave.normal >= 0)
              continue;
            const double xi_c = (master.vertices[0] - xa) * e / (L * L);
            const double xi_d = (master.vertices[1] - xa) * e / (L * L);
            if (std::abs(xi_d - xi_c) < 1e-12)
              continue;
            const double lo = std::max(0., std::min(xi_c, xi_d));
            const double hi = std::min(1., std::max(xi_c, xi_d));
            if (hi - lo < 1e-12)
              continue;
            Candidate    c  = {lo, hi, xi_c, xi_d, 0, &master};
            const double xi = 0.5 * (lo + hi);
            const double s =
              (c.master_point(xi) - (xa + xi * e)) * slave.normal;
            if (s < -L ||
                (interface.maximum_gap > 0 && s > interface.maximum_gap))
              continue;
            c.distance = std::abs(s);
            candidates.push_back(c);
          }
        std::sort(candidates.begin(),
                  candidates.end(),
                  [](const Candidate &a, const Candidate &b) {
                    return a.distance < b.distance;
                  });

        std::vector<std::pair<double, double>> taken;
        for (const Candidate &c : candidates)
          {
            for (const auto &[p0, p1] : uncovered(c.lo, c.hi, taken))
              {
                if (p1 - p0 < 1e-12)
                  continue;
                // Initial overlap: the gap along the face normal is affine
                // on the piece, so its ends bound it. (The weighted gap of a
                // row may be slightly negative where curved sides touch at
                // a point, since psi_j < 0 away from vertex j: that is the
                // mortar condition, not an overlap.)
                for (const double xi : {p0, p1})
                  {
                    const Point<2> xs = xa + xi * e;
                    const double gap = (c.master_point(xi) - xs) * slave.normal;
                    AssertThrow(gap >= -overlap_allowed,
                                ExcMessage(
                                  where + "the slave side at (" +
                                  std::to_string(xs[0]) + ", " +
                                  std::to_string(xs[1]) +
                                  ") penetrates the master side by " +
                                  std::to_string(-gap) +
                                  " m (more than 2 % of the face length, the "
                                  "chord error accepted); initial overlap is "
                                  "not supported"));
                  }
                for (const double q : {-g, g})
                  {
                    const double xi  = 0.5 * (p0 + p1) + 0.5 * (p1 - p0) * q;
                    const double w   = 0.5 * (p1 - p0) * L;
                    const double eta = (xi - c.xi_c) / (c.xi_d - c.xi_c);
                    const std::array<double, 2> psi = {
                      {2 - 3 * xi, 3 * xi - 1}};
                    const std::array<double, 2> phi_master = {{1 - eta, eta}};
                    const Tensor<1, 2>          x_jump =
                      c.master_point(xi) - (xa + xi * e);
                    for (unsigned int j = 0; j < 2; ++j)
                      {
                        const unsigned int key = slave.vertex_keys[j];
                        MortarSums<2>     &row = rows[key];
                        row.weight += w * psi[j];
                        for (unsigned int k = 0; k < 2; ++k)
                          row.master[c.master->dofs[k]] +=
                            w * psi[j] * phi_master[k];
                        row.gap +=
                          w * psi[j] *
                          (x_jump * sides.slaves.at(key).unit_normal());
                      }
                  }
              }
            taken.emplace_back(c.lo, c.hi);
          }
      }

    return normalised_mortar_rows<2>(rows, sides, interface_index, tol);
  }



  template <int dim>
  ContactPairs<dim>
  normalised_mortar_rows(const std::map<unsigned int, MortarSums<dim>> &sums,
                         const ContactSides<dim>                       &sides,
                         const unsigned int interface_index,
                         const double       tol)
  {
    ContactPairs<dim> pairs;
    for (const auto &[key, row] : sums)
      {
        const auto  &vertex = sides.slaves.at(key);
        const double weight = row.weight;
        // A vertex whose faces the master covers for less than a quarter of
        // its weight (at an interface end that overhangs the master) gets
        // no row: int psi_j over a small end piece can be tiny or negative.
        if (weight < 0.25 * vertex.length)
          continue;
        const Tensor<1, dim> n   = vertex.unit_normal();
        const double         gap = row.gap / weight;
        ContactRow           pair;
        pair.interface = interface_index;
        pair.gap       = std::abs(gap) <= tol ? 0. : gap;
        pair.length    = weight;
        // D lumped onto the diagonal (D_jj = W_j, so the row's own
        // coefficient is n_j): where the master covers a slave face only in
        // part, int psi_j phi_i (i != j) is not zero, and keeping it would
        // couple neighbouring slave vertices' rows, whose eliminated dofs
        // would then refer to each other (a cycle no set of constraint lines
        // can hold). Lumping keeps sum_i D_ji = W_j, so rigid translations
        // stay free of the condition; it changes nothing where faces are
        // fully covered (D is diagonal there).
        for (unsigned int d = 0; d < dim; ++d)
          pair.row.emplace_back(vertex.dofs[d], n[d]);
        for (const auto &[dofs, M] : row.master)
          if (M != 0)
            for (unsigned int d = 0; d < dim; ++d)
              pair.row.emplace_back(dofs[d], -M / weight * n[d]);
        pairs.push_back(std::move(pair), {vertex.position, n, vertex.dofs, {}});
      }
    return pairs;
  }



  template ContactPairs<2>
  normalised_mortar_rows(const std::map<unsigned int, MortarSums<2>> &,
                         const ContactSides<2> &,
                         const unsigned int,
                         const double);
  template ContactPairs<3>
  normalised_mortar_rows(const std::map<unsigned int, MortarSums<3>> &,
                         const ContactSides<3> &,
                         const unsigned int,
                         const double);
} // namespace knee_contact
