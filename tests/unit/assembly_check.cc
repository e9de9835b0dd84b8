// The assembled contact problem of qp_scene.prm against the formulas,
// computed here without the program's assembly or pairing code, so that the
// premise of qp_enumeration.cc (the QP it enumerates is the right one) is
// itself verified.
//
// The scene: a soft block [0,2]x[0,1] (3x2 cells, E = 1e9, nu = 0.3) under a
// stiff block [0,2]x[1,1.5] (4x1 cells, E = 2e9, nu = 0.25), plane strain;
// top traction (0, -1e6 (x - 0.8)); the upper block's bottom (slave) on the
// lower block's top (master), non-matching. Computed here:
// - the stiffness matrix: bilinear Q1 on each rectangle, B^T D B at 2x2
//   Gauss points (exact for rectangles), D of plane strain from E and nu;
// - the load: consistent nodal forces of the linear traction on each top
//   edge, L (2 t_a + t_b) / 6;
// - the contact rows: each slave vertex x_s projected along the slave's
//   outward normal (0, -1) onto the master segment [x_a, x_b] holding it,
//   xi = (x_s - x_a) / (x_b - x_a): row = n . (u_s - (1 - xi) u_a - xi u_b),
//   gap 0, the vertex's share of slave length (0.25 at the ends, 0.5 inside).
// The program's DoFHandler is used only to find the dof index of a vertex of
// a cell (cells matched by centre, vertices by position: dof_at()).
// Asserted: matrix, load and rows equal to 1e-12 relative to their largest
// entries, the same pairs, the same gaps and lengths; and the mortar rows of
// the same scene (see below).

#include <knee_contact/core/problem.h>

#include <deal.II/lac/full_matrix.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <iostream>

using namespace dealii;
using namespace knee_contact;

namespace
{
  struct Block
  {
    double       x0, y0, x1, y1;
    unsigned int nx, ny;
    double       E, nu;
  };

  // Element stiffness of a bilinear rectangle, dofs ordered (vertex a,
  // component d) -> 2 a + d with vertices (x0,y0), (x1,y0), (x0,y1), (x1,y1).
  FullMatrix<double>
  element_stiffness(const double hx,
                    const double hy,
                    const double E,
                    const double nu)
  {
    const double       lambda  = E * nu / ((1 + nu) * (1 - 2 * nu));
    const double       mu      = E / (2 * (1 + nu));
    const double       D[3][3] = {{lambda + 2 * mu, lambda, 0},
                                  {lambda, lambda + 2 * mu, 0},
                                  {0, 0, mu}};
    const double       sx[4] = {-1, 1, -1, 1}, sy[4] = {-1, -1, 1, 1};
    const double       g = 1 / std::sqrt(3.);
    FullMatrix<double> K(8, 8);
    for (const double xi : {-g, g})
      for (const double eta : {-g, g})
        {
          // B (3 x 8): strains (e_xx, e_yy, 2 e_xy).
          double B[3][8] = {};
          for (unsigned int a = 0; a < 4; ++a)
            {
              const double dNdx = sx[a] * (1 + sy[a] * eta) / 4 * 2 / hx;
              const double dNdy = sy[a] * (1 + sx[a] * xi) / 4 * 2 / hy;
              B[0][2 * a]       = dNdx;
              B[1][2 * a + 1]   = dNdy;
              B[2][2 * a]       = dNdy;
              B[2][2 * a + 1]   = dNdx;
            }
          const double w = hx * hy / 4; // weights 1, Jacobian hx hy / 4
          for (unsigned int i = 0; i < 8; ++i)
            for (unsigned int j = 0; j < 8; ++j)
              for (unsigned int k = 0; k < 3; ++k)
                for (unsigned int l = 0; l < 3; ++l)
                  K(i, j) += B[k][i] * D[k][l] * B[l][j] * w;
        }
    return K;
  }

  // The dof of component d at the vertex p of the cell whose centre is c:
  // the program's DoFHandler is used for its numbering only.
  types::global_dof_index
  dof_at(const DoFHandler<2> &dofs,
         const Point<2>      &c,
         const Point<2>      &p,
         const unsigned int   d)
  {
    for (const auto &cell : dofs.active_cell_iterators())
      if (cell->center().distance(c) < 1e-12)
        for (const unsigned int v : cell->vertex_indices())
          if (cell->vertex(v).distance(p) < 1e-12)
            return cell->vertex_dof_index(v, d);
    std::cerr << "no vertex " << p << " in the cell at " << c << std::endl;
    std::exit(1);
  }



  double
  max_abs(const FullMatrix<double> &M)
  {
    double m = 0;
    for (unsigned int i = 0; i < M.m(); ++i)
      for (unsigned int j = 0; j < M.n(); ++j)
        m = std::max(m, std::abs(M(i, j)));
    return m;
  }
} // namespace

int
main()
{
  ContactProblem<2> problem(SOURCE_DIR "/qp_scene.prm");
  const int         status = problem.run();

  const DoFHandler<2> &dofs = problem.dof_handler_of();
  const unsigned int   n    = dofs.n_dofs();


  const std::array<Block, 2> blocks = {
    {{0, 0, 2, 1, 3, 2, 1e9, 0.3}, {0, 1, 2, 1.5, 4, 1, 2e9, 0.25}}};
  FullMatrix<double> K(n, n);
  Vector<double>     f(n);
  for (const Block &b : blocks)
    {
      const double hx = (b.x1 - b.x0) / b.nx, hy = (b.y1 - b.y0) / b.ny;
      const FullMatrix<double> Ke = element_stiffness(hx, hy, b.E, b.nu);
      for (unsigned int i = 0; i < b.nx; ++i)
        for (unsigned int j = 0; j < b.ny; ++j)
          {
            const Point<2>          lower(b.x0 + i * hx, b.y0 + j * hy);
            const Point<2>          centre = lower + Point<2>(hx / 2, hy / 2);
            std::array<Point<2>, 4> corner = {{lower,
                                               lower + Point<2>(hx, 0),
                                               lower + Point<2>(0, hy),
                                               lower + Point<2>(hx, hy)}};
            std::array<types::global_dof_index, 8> index;
            for (unsigned int a = 0; a < 4; ++a)
              for (unsigned int d = 0; d < 2; ++d)
                index[2 * a + d] = dof_at(dofs, centre, corner[a], d);
            for (unsigned int k = 0; k < 8; ++k)
              for (unsigned int l = 0; l < 8; ++l)
                K(index[k], index[l]) += Ke(k, l);
            // Traction on the top of the upper block.
            if (b.y1 == 1.5 && j + 1 == b.ny)
              {
                const auto t = [](const double x) { return -1e6 * (x - 0.8); };
                const double xa = corner[2][0], xb = corner[3][0];
                f(index[5]) += hx * (2 * t(xa) + t(xb)) / 6;
                f(index[7]) += hx * (t(xa) + 2 * t(xb)) / 6;
              }
          }
    }

  // Contact rows: slave = the upper block's bottom vertices.
  const unsigned int          n_slave = 5, n_master = 4;
  std::vector<Vector<double>> rows(n_slave, Vector<double>(n));
  std::vector<double>         lengths(n_slave);
  std::vector<Point<2>>       positions(n_slave);
  for (unsigned int s = 0; s < n_slave; ++s)
    {
      const double   hs = 0.5, hm = 2. / 3;
      const Point<2> xs(s * hs, 1);
      positions[s] = xs;
      lengths[s]   = (s == 0 || s + 1 == n_slave) ? hs / 2 : hs;
      const Point<2> slave_cell(std::min(s, n_slave - 2) * hs + hs / 2, 1.25);
      // n . u_s with n = (0, -1)
      rows[s](dof_at(dofs, slave_cell, xs, 1)) += -1;
      const unsigned int m =
        std::min<unsigned int>(std::floor(xs[0] / hm), n_master - 2);
      const double   xi = (xs[0] - m * hm) / hm;
      const Point<2> master_cell(m * hm + hm / 2, 0.75);
      rows[s](dof_at(dofs, master_cell, Point<2>(m * hm, 1), 1)) += (1 - xi);
      rows[s](dof_at(dofs, master_cell, Point<2>((m + 1) * hm, 1), 1)) += xi;
    }

  // Compare.
  FullMatrix<double> K_program(n, n);
  K_program.copy_from(problem.matrix());
  FullMatrix<double> dK(K_program);
  dK.add(-1, K);
  const double   matrix_error = max_abs(dK) / max_abs(K);
  Vector<double> df(problem.rhs());
  df -= f;
  const double load_error = df.linfty_norm() / f.linfty_norm();

  const auto  &pairs     = problem.pairs();
  double       row_error = pairs.size() == n_slave ? 0 : 1;
  double       gap_error = 0, length_error = 0;
  unsigned int matched = 0;
  for (unsigned int p = 0; p < pairs.size(); ++p)
    for (unsigned int s = 0; s < n_slave; ++s)
      if (pairs.points[p].position.distance(positions[s]) < 1e-12)
        {
          ++matched;
          const ContactRow &pair = pairs.rows[p];
          Vector<double>    row(n);
          for (const auto &[dof, a] : pair.row)
            row(dof) += a;
          row -= rows[s];
          row_error = std::max(row_error, row.linfty_norm());
          gap_error = std::max(gap_error, std::abs(pair.gap));
          length_error =
            std::max(length_error, std::abs(pair.length - lengths[s]));
        }

  std::cout << "pairs " << pairs.size() << " (formula " << n_slave
            << "), matched by position " << matched << std::endl;
  bool       pass   = status == 0 && matched == n_slave;
  const auto report = [&](const char *what, const double value) {
    const bool ok = value <= 1e-12;
    pass          = pass && ok;
    std::cout << "check " << what << " <= 1e-12: " << (ok ? "PASS" : "FAIL")
              << std::endl;
  };
  report("stiffness matrix, max |K - K_formula| / max |K_formula|",
         matrix_error);
  report("load, max |f - f_formula| / max |f_formula|", load_error);
  report("contact rows, max |a_p - a_formula|", row_error);
  report("gaps, max |g_p|", gap_error);
  report("slave length shares, max |l_p - l_formula|", length_error);

  // Mortar rows of the same scene (qp_scene_mortar.prm): for slave vertex j,
  // with the global dual function psi_j (3 phi_j - 1 on each slave face at
  // j, 0 elsewhere) and the master hat functions phi_k,
  //   row_j = n.u_j - sum_k (M_jk / W_j) n.u_k,  M_jk = int psi_j phi_k,
  //   W_j = int psi_j (= the vertex's length share), gap 0 (flat, touching),
  // integrated here by Simpson's rule between all slave and master vertices
  // (the integrand is quadratic on each piece, so Simpson is exact): a
  // different rule and a global instead of a face-by-face formulation.
  ContactProblem<2> mortar(SOURCE_DIR "/qp_scene_mortar.prm");
  pass                             = pass && mortar.run() == 0;
  const DoFHandler<2> &mortar_dofs = mortar.dof_handler_of();
  const auto           mortar_dof  = [&](const Point<2> &c, const Point<2> &p) {
    return dof_at(mortar_dofs, c, p, 1);
  };
  const double hs = 0.5, hm = 2. / 3;
  const auto   hat = [](const double x, const double node, const double h) {
    return std::max(0., 1 - std::abs(x - node) / h);
  };
  const auto psi = [&](const unsigned int j, const double x) {
    // The slave face holding x (x inside a face, never at a vertex here).
    const double face = std::floor(x / hs);
    if (j != face && j != face + 1)
      return 0.;
    return 3 * hat(x, j * hs, hs) - 1;
  };
  std::vector<double> breaks = {0, hm, 2 * hm, 2};
  for (unsigned int s = 0; s < n_slave; ++s)
    breaks.push_back(s * hs);
  std::sort(breaks.begin(), breaks.end());
  double mortar_error = mortar.pairs().size() == n_slave ? 0 : 1;
  for (unsigned int p = 0; p < mortar.pairs().size(); ++p)
    {
      const ContactRow  &pair = mortar.pairs().rows[p];
      const unsigned int j =
        std::lround(mortar.pairs().points[p].position[0] / hs);
      Vector<double>      expected(mortar_dofs.n_dofs());
      double              W = 0;
      std::vector<double> M(n_master);
      for (unsigned int b = 0; b + 1 < breaks.size(); ++b)
        {
          const double x0 = breaks[b], x1 = breaks[b + 1];
          if (x1 - x0 < 1e-14)
            continue;
          for (const auto &[x, w] : {std::pair{x0 + 1e-14, 1.},
                                     std::pair{0.5 * (x0 + x1), 4.},
                                     std::pair{x1 - 1e-14, 1.}})
            {
              const double weight = w * (x1 - x0) / 6;
              W += weight * psi(j, x);
              for (unsigned int k = 0; k < n_master; ++k)
                M[k] += weight * psi(j, x) * hat(x, k * hm, hm);
            }
        }
      const Point<2> slave_cell(std::min(j, n_slave - 2) * hs + hs / 2, 1.25);
      expected(mortar_dof(slave_cell, Point<2>(j * hs, 1))) += -1;
      for (unsigned int k = 0; k < n_master; ++k)
        {
          const Point<2> master_cell(std::min(k, n_master - 2) * hm + hm / 2,
                                     0.75);
          expected(mortar_dof(master_cell, Point<2>(k * hm, 1))) += M[k] / W;
        }
      Vector<double> row(mortar_dofs.n_dofs());
      for (const auto &[dof, a] : pair.row)
        row(dof) += a;
      row -= expected;
      mortar_error = std::max({mortar_error,
                               row.linfty_norm(),
                               std::abs(pair.gap),
                               std::abs(pair.length - W)});
    }
  std::cout << "mortar pairs " << mortar.pairs().size() << std::endl;
  report("mortar rows, gaps and weights, max difference", mortar_error);
  return pass ? 0 : 1;
}
