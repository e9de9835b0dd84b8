#ifndef knee_contact_contact_h
#define knee_contact_contact_h

#include <knee_contact/contact/contact_row.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <deal.II/lac/affine_constraints.h>

#include <deal.II/dofs/dof_handler.h>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Where a contact row sits: the slave vertex x_p and the unit normal n_p
   * of its row a_p x <= g_p (ContactRow), for output and refinement; the
   * solver never sees it. Node-to-segment rows read
   *   n_p . (u^k(x_p) - u^l(y_p)) <= g_p,   g_p = n_p . (y_p - x_p),
   * with y_p where n_p meets the master side (matching meshes: a master
   * vertex, the seed's node pairs); mortar rows weigh the master side's
   * displacement over the slave vertex's support instead.
   */
  template <int dim>
  struct ContactPoint
  {
    Point<dim>     position;
    Tensor<1, dim> normal;
    /** Dof indices of the slave vertex (x, y[, z]). */
    std::array<types::global_dof_index, dim> slave_dofs;
    /**
     * With friction: the unit tangents of the pair's tangential rows. 2D:
     * that of the common normal n - n_master (n_master: the master face
     * the slave normal meets), t = (-m_y, m_x) for m the common normal; on
     * curved sides both normals tilt over the contact zone, and the
     * slave's alone would count part of the normal approach as slip. 3D:
     * two orthonormal tangents of the slave normal n (t_2 = n x t_1; the
     * slave normal of a 3D row is its mortar-averaged nodal normal, which
     * already leans on both sides' geometry).
     */
    std::array<Tensor<1, dim>, dim - 1> tangents;
  };



  /**
   * The Cartesian vector of a pair's tangential quantity @p v (multiplier,
   * slip) given along its tangents: sum_j v_j t_j.
   */
  template <int dim>
  Tensor<1, dim>
  tangential_vector(const ContactPoint<dim> &point, const TangentialVector &v)
  {
    Tensor<1, dim> cartesian;
    for (unsigned int j = 0; j + 1 < dim; ++j)
      cartesian += v[j] * point.tangents[j];
    return cartesian;
  }



  /**
   * How a frictional pair's stick rows S_k (the k-th component of the
   * weighted jump, which hold it while it sticks) and its normal and
   * tangential rows N, T_j combine: with F the matrix of rows n, t_1[, t_2],
   * [N; T] = F S, so S_k = sum_i c[k][i] [N; T]_i and the multipliers
   * [lambda_n; lambda_t] = c^T lambda_S, c = F^-1. Entries beyond dim are
   * zero.
   */
  template <int dim>
  StickCoefficients
  stick_coefficients(const Tensor<1, dim>                      &n,
                     const std::array<Tensor<1, dim>, dim - 1> &t)
  {
    Tensor<2, dim> F;
    for (unsigned int d = 0; d < dim; ++d)
      {
        F[0][d] = n[d];
        for (unsigned int j = 0; j + 1 < dim; ++j)
          F[1 + j][d] = t[j][d];
      }
    const Tensor<2, dim> inverse = invert(F);
    StickCoefficients    c{};
    for (unsigned int k = 0; k < dim; ++k)
      for (unsigned int i = 0; i < dim; ++i)
        c[k][i] = inverse[k][i];
    return c;
  }



  /**
   * The contact rows of a mesh and, index by index, their points.
   */
  template <int dim>
  struct ContactPairs
  {
    std::vector<ContactRow>        rows;
    std::vector<ContactPoint<dim>> points;
    /**
     * With friction on any interface: for each row p and tangent j the
     * tangential row t_j . (u_slave - u_master) [rows[p]'s weights, the
     * tangent points[p].tangents[j] in place of n], gap 0 (loaded in one
     * step; along a load path the last case's jump); empty if no
     * interface has friction.
     */
    std::array<std::vector<ContactRow>, dim - 1> tangential;
    /**
     * With friction: the rows that hold a sticking pair, the components
     * e_k . (u_slave - u_master) with rows[p]'s weights (see make_pairs).
     */
    std::array<std::vector<ContactRow>, dim> stick;

    /** Whether any interface has friction (the rows above exist). */
    bool
    frictional() const
    {
      return !tangential[0].empty();
    }

    /**
     * The rows the solver sees, as FrictionRowLayout orders them: the
     * normal rows, then the tangential, then the stick rows.
     */
    std::vector<ContactRow>
    solver_rows() const
    {
      std::vector<ContactRow> all = rows;
      for (const auto &more : tangential)
        all.insert(all.end(), more.begin(), more.end());
      for (const auto &more : stick)
        all.insert(all.end(), more.begin(), more.end());
      return all;
    }

    std::size_t
    size() const
    {
      return rows.size();
    }

    bool
    empty() const
    {
      return rows.empty();
    }

    void
    push_back(ContactRow &&row, const ContactPoint<dim> &point)
    {
      rows.push_back(std::move(row));
      points.push_back(point);
    }
  };



  /**
   * The contact CSV of an interface: contact_<name>.csv with every
   * character but letters, digits and '-' replaced by '_'.
   */
  std::string
  csv_file_name(const std::string &interface_name);



  /**
   * How an interface's contact conditions are discretised (the seam: each
   * has its row builder in contact_sides.h).
   */
  enum class Pairing
  {
    mortar,
    node_to_segment,
    node_to_node
  };

  /** The name of a Pairing as in the scene files. */
  std::string
  pairing_name(const Pairing pairing);



  /** The friction law of an interface. */
  enum class Friction
  {
    none,
    tresca,
    coulomb
  };

  struct ContactInterface
  {
    std::string        name;
    types::boundary_id slave_id    = 0;
    types::boundary_id master_id   = 0;
    Pairing            pairing     = Pairing::mortar;
    double             maximum_gap = 0;
    Friction           friction    = Friction::none;
    /** Coulomb: |tau_t| <= mu p. */
    double friction_coefficient = 0;
    /** Tresca: |tau_t| <= this bound [Pa]. */
    double tresca_bound = 0;
  };



  /**
   * The contact interfaces of a scene and their pairing. No library pairs
   * nodes across bodies for this formulation, so it is written here.
   */
  class ContactInterfaces
  {
  public:
    /**
     * Declare the subsection "Contact" with the subsections 'Interface 0'
     * ... 'Interface @p n_interfaces - 1', each entry bound to the member it
     * sets.
     */
    void
    add_parameters(ParameterHandler &prm, const unsigned int n_interfaces);

    /**
     * After parsing: the checks the patterns cannot make (names valid and
     * distinct as file names, two sides, no boundary id in two
     * interfaces).
     */
    void
    check_parameters() const;

    /** 'Number of interfaces' as the scene gives it. */
    unsigned int n_interfaces = 0;

    /**
     * Throw if a side's boundary id is missing, or both sides of an
     * interface lie on the same body.
     */
    template <int dim>
    void
    check_mesh(const Triangulation<dim>        &triangulation,
               const std::vector<unsigned int> &body_ids) const;

    /**
     * Pair every slave vertex of every interface (see ContactPoint), and
     * choose each row's eliminated dof given the Gamma_u/Gamma_o
     * @p constraints (closed). 2D and 3D, with friction the tangential and
     * stick rows too.
     *
     * On a distributed mesh (DistributedMesh) @p vertex_id names each
     * vertex a rank holds by the whole mesh's index: each rank collects the
     * sides' faces of the cells it owns and every rank gathers them all
     * (the sides are a surface's worth), keyed as the whole mesh keys
     * them, so that every rank makes the same rows, in the whole mesh's
     * order, on the distributed dofs; @p constraints must then hold the
     * lines of every dof of the sides. Null on a whole mesh.
     */
    template <int dim>
    ContactPairs<dim>
    make_pairs(const DoFHandler<dim>           &dof_handler,
               const AffineConstraints<double> &constraints,
               const std::vector<unsigned int> *vertex_id = nullptr) const;

    const std::vector<ContactInterface> &
    interfaces() const
    {
      return list;
    }

  private:
    std::vector<ContactInterface> list;
  };

  /**
   * The weight of each cell of a whole mesh of one level (by
   * active_cell_index()) in the partition of a parallel run: its share of
   * the entries its vertices' rows will have in the condensed system's
   * pattern (ActiveSetSolver::make_sparsity_pattern(), counted by vertex),
   * estimated before there are dofs or contact rows. A contact row widens
   * the rows near its slave vertex by the master vertices it refers to and
   * gives those masters its neighbourhood's columns: on the 3D knee at 2.3e5
   * dofs the pattern of every set held 4.4e6 entries beyond the mesh's
   * 1.04e7, three quarters of them on the rank of the master side, so that
   * a partition of equal cells gave one of two ranks 8.4e6 entries and the
   * other 6.3e6 (doc/parallel.md). Here each slave vertex refers to the
   * master faces near its faces (mortar_rows()'s candidates) whose discs
   * meet a slave face's along it: about the masters a row keeps. Written
   * here because it needs the contact sides and no library knows them;
   * distribute_mesh() balances these weights together with the rows.
   */
  template <int dim>
  std::vector<double>
  partition_weights(const Triangulation<dim> &whole,
                    const ContactInterfaces  &interfaces);

} // namespace knee_contact

#endif
