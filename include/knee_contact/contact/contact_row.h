#ifndef knee_contact_contact_row_h
#define knee_contact_contact_row_h

#include <deal.II/base/types.h>

#include <deal.II/lac/vector.h>

#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /** sum_i c_i x_i over the (dof, coefficient) pairs @p entries. */
  inline double
  sparse_dot(
    const std::vector<std::pair<types::global_dof_index, double>> &entries,
    const Vector<double>                                          &x)
  {
    double value = 0;
    for (const auto &[dof, coefficient] : entries)
      value += coefficient * x(dof);
    return value;
  }



  /**
   * One row of the seed's contact constraint A x <= 0 (its eq. (13)), with
   * the initial gap: a_p . x <= g_p, as the solver sees it. It knows dofs and
   * coefficients only, no geometry (positions and normals are in
   * ContactPoint, for output), so that the solver is the same in 2D and 3D
   * and for every contact discretisation (node-to-node, node-to-segment,
   * mortar) that makes rows.
   */
  struct ContactRow
  {
    /** The contact interface the row belongs to. */
    unsigned int interface = 0;
    /** g_p [m]. */
    double gap = 0;
    /**
     * The row's weight [m in 2D, m^2 in 3D]: the slave vertex's share of the
     * slave boundary; the multiplier divided by it is a pressure [Pa].
     */
    double length = 0;

    /** The row a_p: (dof, coefficient). */
    std::vector<std::pair<types::global_dof_index, double>> row;
    /**
     * The row with the Gamma_u and Gamma_o constraints substituted, over
     * dofs those leave free, and its right hand side.
     */
    std::vector<std::pair<types::global_dof_index, double>> reduced_row;
    double                                                  reduced_gap = 0;
    /**
     * The dof an active row eliminates (a free slave component if there is
     * one, else a free master component); invalid if the row has no free
     * dof left, i.e. Gamma_u or Gamma_o already decide it.
     */
    types::global_dof_index eliminated       = numbers::invalid_dof_index;
    bool                    slave_eliminated = true;
    /**
     * A row the loop only measures and never holds as an equality (the
     * tangential rows of a frictional pair: its slip; a sticking pair is
     * held by its stick rows). The condensed path leaves it
     * out of its per-iteration system, and the solver choice counts it.
     */
    bool measured_only = false;
    /**
     * A frictional pair's stick row (ContactPairs::stick): active only
     * while the pair sticks, which on a sliding interface few pairs do.
     * The condensed path takes it into its per-iteration system only then.
     */
    bool stick = false;

    /**
     * Whether Gamma_u and Gamma_o alone make the row hold (nothing of it
     * is left after their substitution).
     */
    bool
    held_by_conditions() const
    {
      for (const auto &entry : reduced_row)
        if (std::abs(entry.second) > 1e-12)
          return false;
      return true;
    }

    /**
     * The slave vertex's spacing [m] in a mesh of dimension @p dim: the
     * weight itself in 2D, the square root of the area share in 3D.
     */
    double
    spacing(const unsigned int dim) const
    {
      return std::pow(length, 1. / (dim - 1));
    }

    /** a_p . x */
    double
    jump(const Vector<double> &x) const
    {
      return sparse_dot(row, x);
    }
  };



  /**
   * Where the rows of frictional pair p sit in the solver's list
   * (ContactPairs::solver_rows()): the n normal rows N, then dim - 1
   * blocks of n tangential rows T_j, then dim blocks of n stick rows S_k.
   */
  struct FrictionRowLayout
  {
    unsigned int n_pairs = 0;
    unsigned int dim     = 2;

    unsigned int
    normal(const unsigned int p) const
    {
      return p;
    }

    unsigned int
    tangential(const unsigned int j, const unsigned int p) const
    {
      return (1 + j) * n_pairs + p;
    }

    unsigned int
    stick(const unsigned int k, const unsigned int p) const
    {
      return (dim + k) * n_pairs + p;
    }

    unsigned int
    size() const
    {
      return 2 * dim * n_pairs;
    }
  };

  /**
   * A frictional pair's stick_coefficients() (contact.h): up to 3 x 3, the
   * entries beyond dim zero.
   */
  using StickCoefficients = std::array<std::array<double, 3>, 3>;

  /**
   * A tangential quantity of a pair (multiplier, slip) by its components
   * along the pair's dim - 1 tangents; the second is zero in 2D.
   */
  using TangentialVector = std::array<double, 2>;

  /** Its length. */
  inline double
  magnitude(const TangentialVector &v)
  {
    return std::sqrt(v[0] * v[0] + v[1] * v[1]);
  }
} // namespace knee_contact

#endif
