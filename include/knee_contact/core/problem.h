#ifndef knee_contact_problem_h
#define knee_contact_problem_h

#include <knee_contact/contact/contact.h>
#include <knee_contact/mesh/distributed_mesh.h>
#include <knee_contact/mesh/mesh.h>
#include <knee_contact/physics/boundary_conditions.h>
#include <knee_contact/physics/materials.h>
#include <knee_contact/physics/rigid_modes.h>
#include <knee_contact/physics/rigid_motions.h>
#include <knee_contact/postprocess/load_cases.h>
#include <knee_contact/postprocess/output.h>
#include <knee_contact/postprocess/problem_access.h>
#include <knee_contact/postprocess/recovery.h>
#include <knee_contact/postprocess/refinement.h>
#include <knee_contact/postprocess/results.h>
#include <knee_contact/postprocess/study.h>
#include <knee_contact/postprocess/verification.h>
#include <knee_contact/solver/active_set.h>
#include <knee_contact/solver/contact_system.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/timer.h>

#include <deal.II/lac/affine_constraints.h>
#include <deal.II/lac/sparse_matrix.h>
#include <deal.II/lac/sparsity_pattern.h>
#include <deal.II/lac/trilinos_sparsity_pattern.h>
#include <deal.II/lac/vector.h>

#include <deal.II/dofs/dof_handler.h>
#include <deal.II/fe/fe_system.h>
#include <deal.II/grid/tria.h>

#include <functional>
#include <map>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Exit codes of the program.
   */
  enum ExitCode : int
  {
    success             = 0,
    input_error         = 1,
    verification_failed = 2,
    not_converged       = 3,
    internal_error      = 4
  };



  /**
   * The dimension a scene is solved in: 3 if its mesh file has volume cells,
   * else 2 (see the mesh's scene_dimension()).
   */
  unsigned int
  scene_dimension(const std::string &scene_file);



  /**
   * The contact problem of the seed: s linear elastic bodies with
   * Gamma_u, Gamma_tau, Gamma_o and unilateral contact on Gamma_c, solved
   * on one or more meshes, in 2D or 3D (the dimension of the mesh:
   * scene_dimension()). It orchestrates: scene -> dofs and constraints
   * -> assembled system -> active-set loop -> results -> files. Each step
   * is done by the class of its concept.
   */
  template <int dim>
  class ContactProblem
  {
  public:
    /**
     * How many numbered subsections a scene file has; read in a first pass
     * so that the second pass can declare exactly those.
     */
    struct Counts
    {
      unsigned int n_materials  = 1;
      unsigned int n_conditions = 1;
      unsigned int n_interfaces = 1;
      unsigned int n_motions    = 1;
    };

    static Counts
    read_counts(const std::string &scene_file);

    /**
     * Every parameter of a scene with its pattern, default and
     * documentation (knee_contact --print-parameters).
     */
    static void
    print_parameters(std::ostream &out);

    /**
     * Read the scene file; throws a one-line message on bad input.
     */
    explicit ContactProblem(const std::string &scene_file);

    /**
     * Build the mesh and check it against the scene, without solving.
     */
    void
    check_scene();

    /**
     * Solve on every refinement cycle, write the files of the last one,
     * and return an ExitCode.
     */
    int
    run();

    // Access for unit tests.
    Results<dim>
    results_of_solution() const
    {
      return current_results();
    }
    ActiveSetSolver &
    contact_solver()
    {
      return active_set_solver;
    }
    const Materials<dim> &
    materials_of() const
    {
      return materials;
    }
    const BoundaryConditions<dim> &
    boundary_conditions_of() const
    {
      return boundary_conditions;
    }
    const ContactInterfaces &
    contact_interfaces_of() const
    {
      return contact_interfaces;
    }
    const DoFHandler<dim> &
    dof_handler_of() const
    {
      return dof_handler;
    }
    const SparseMatrix<double> &
    matrix() const
    {
      return system_matrix;
    }
    const Vector<double> &
    rhs() const
    {
      return system_rhs;
    }
    const AffineConstraints<double> &
    base_constraints() const
    {
      return constraints;
    }
    const ContactPairs<dim> &
    pairs() const
    {
      return contact_pairs;
    }
    const Vector<double> &
    solution() const
    {
      return displacement;
    }
    const ContactSolution &
    contact() const
    {
      return contact_solution;
    }

    /**
     * The influence (dual) solution of the multiplier lambda_p of contact
     * pair @p p, with the active set of the last solve held (frictionless):
     * z with C z + A_active^T mu = 0 under the homogeneous constraints and
     * a_q . z = delta_pq for the active pairs q, so that a change dd of the
     * load changes lambda_p by z . dd (the KKT matrix is symmetric). By
     * linearity it is (x(g + s e_p) - x(g)) / s: one more solve of the
     * factorised contact system with the pair's gap moved by s (the
     * gaps are restored after). @p mu receives the multipliers of z.
     */
    Vector<double>
    multiplier_influence(const std::vector<unsigned int> &pairs,
                         std::vector<double>             &mu);

  private:
    /** The parts without a scene: for read_counts() and print_parameters(). */
    ContactProblem() = default;

    /**
     * Declare every part's parameters, bound to the parts' members, with
     * the numbered subsections of @p counts.
     */
    void
    add_parameters(ParameterHandler &prm, const Counts &counts);

    /**
     * The mesh at refinement @p level: 0 on the first cycle; > 0 where the
     * mesh input remeshes instead of refining (MeshInput::remeshes()) or
     * the distributed mesh of a uniform sequence is made anew;
     * @p distributed: rank 0 makes it to divide it (its memory check).
     */
    void
    make_mesh(const int level, const bool distributed = false);

    /**
     * Why this mesh (the whole one make_mesh() made) is to be distributed
     * over the ranks, or empty where the run keeps it whole on every rank.
     * It is distributed where the iterative path will solve on several
     * ranks (Contact/Solver = iterative, or the automatic choice in 3D at
     * min_distributed_dofs and more without friction, which it keeps on a
     * direct path) and the mesh is not refined in place:
     * a uniform sequence (each cycle's mesh made whole anew, make_mesh()
     * at its level, and distributed), no adaptive cycles (a fully
     * distributed mesh cannot be refined) and no moved bodies (Load
     * cases/Motion moves and turns the whole mesh).
     */
    std::string
    distribution_reason(const Refinement::Strategy strategy) const;

    /**
     * Whether the scene alone (before its mesh is made) lets the run
     * distribute its mesh: distribution_reason() without the automatic
     * choice's count of DoFs.
     */
    bool
    may_distribute(const Refinement::Strategy strategy) const;

    /**
     * The mesh of a cycle at @p level where it may be distributed
     * (may_distribute()): rank 0 alone makes and checks it whole
     * (make_mesh()) and decides (distribution_reason()) while the others
     * wait asleep; they take its refusal (said once) or its decision. A
     * mesh to distribute is divided from rank 0's (distribute()), so that
     * no other rank ever holds the whole mesh; one the automatic choice
     * keeps whole (below min_distributed_dofs) is made on every rank as
     * make_mesh() does.
     */
    void
    make_distributable_mesh(const int                  level,
                            const Refinement::Strategy strategy);

    /** The distributed mesh, if any, let go of (every rank). */
    void
    release_distributed_mesh();

    /** The run's phases from @p timer and the mesh phase's steps
     * (mesh_times, as "mesh: <step>") [s]. */
    std::map<std::string, double>
    phase_times(const TimerOutput &timer) const;

    /**
     * 3D meshes from this many DoFs take the distributed mesh under the
     * automatic choice: the iterative path was measured faster than the
     * direct ones on the 3D knee from 3.4e4 DoFs (doc/performance.md), and
     * the Hertz sphere's condensed path, faster at 4.8e4, has a factor
     * growing as n^(4/3) (refused on 24 GB at 6e5).
     */
    static constexpr double min_distributed_dofs = 2e5;

    /**
     * Divide the whole mesh rank 0's make_mesh() made over the ranks
     * (distribute_mesh()) and free it; the rest of the cycle runs on
     * distributed->triangulation. The other ranks take what they did not
     * make from rank 0: the bodies, their names and the cells' kind.
     */
    void
    distribute();

    /** The mesh the run is on: the distributed one if any, else the whole. */
    const Triangulation<dim> &
    mesh() const
    {
      return distributed ? distributed->triangulation : triangulation;
    }

    /** The cells of the mesh the run is on, over all ranks. */
    types::global_cell_index
    n_cells() const
    {
      return mesh().n_global_active_cells();
    }

    /** body_names from the whole mesh's cells and body_of_cell. */
    void
    name_bodies();

    void
    setup_system();

    /**
     * The solver path, chosen from C's pattern (solver_plan), then C and d:
     * C whole into system_matrix, or where the path assembles the rows it
     * holds (the iterative path on several ranks) d alone and the contact
     * system, which takes its rows. @p warm_start: the loop will start from
     * a guess (the choice expects fewer iterations).
     */
    void
    assemble_system(const bool warm_start);

    /** contact_system, solver_name and solver_figures from solver_plan. */
    void
    make_solver();

    /**
     * Solve on Refinement::n_cycles meshes refined by @p strategy, starting
     * from the coarse mesh; one record per cycle. Leaves the last solution
     * in place and its derived quantities in @p results.
     */
    std::vector<CycleRecord>
    run_cycles(const Refinement::Strategy strategy,
               TimerOutput               &timer,
               Results<dim>              &results);

    /**
     * Contact/Coarse start levels: solve on the meshes @p levels, ..., 1
     * levels coarser than the first cycle's, each from the previous one's
     * contact zone, and leave the last zone in previous_contact as the
     * first cycle's guess. Returns the time it took. A coarser mesh that
     * cannot be made or solved only costs the guess (said in the log).
     */
    double
    coarse_start(const unsigned int levels);

    /** The active pairs' places and spacings, kept in previous_contact. */
    void
    keep_contact_zone();

    /**
     * The pairs within a kept active pair's spacing (the previous mesh's
     * contact zone); empty if none is kept.
     */
    std::vector<bool>
    previous_zone_guess() const;

    /**
     * Solve the contact problem for the current system_rhs, from the active
     * set @p guess: with a new contact system (factorisation) if
     * @p new_matrix, else reusing the last one (a further load case). With
     * friction, @p continue_path: the case continues a load path on a new
     * system (move_to_case() held the rows and carried the slip over).
     */
    void
    solve_contact(const std::vector<bool> &guess,
                  const bool               new_matrix,
                  const bool               continue_path = false);

    /**
     * A further load case with Load cases/Motion: place the moved bodies
     * from the pose at @p t_from to that at @p t_to, find the pairs again,
     * assemble, and carry each slave vertex's state over (its active flag,
     * returned as the guess, its accumulated slip, and with friction the
     * tangential rows held where the previous case left the pair: its
     * elastic jump, turned with the bodies, less the rigid sliding since).
     */
    std::vector<bool>
    move_to_case(const double t_from, const double t_to);

    /** The derived quantities (compute_results()) of the current solution. */
    Results<dim>
    current_results() const;

    /** The read-only view of this problem its collaborators take. */
    ProblemAccess<dim>
    access() const;

    /**
     * The reported quantities of @p results by the names the error
     * estimates and Refinement/Target quantity use: "energy", "peak
     * pressure" (the largest of the interfaces), "interface NAME: peak
     * pressure", "interface NAME: force", "interface NAME: contact length",
     * "MATERIAL: tau_yy min", "MATERIAL: tau_yy max", "MATERIAL: von Mises
     * max".
     */
    Quantities
    cycle_quantities(const Results<dim> &results) const;

    /** Evaluate loads and exact solutions at load parameter @p t. */
    void
    set_load_parameter(const double t);

    /**
     * The files of one solution into the output writer's current folder:
     * VTU, cells.npy, contact CSVs, study.csv for a study, summary.json and
     * pictures.
     */
    void
    write_result_set(const Results<dim>                          &results,
                     const std::vector<std::vector<CycleRecord>> &sequences,
                     TimerOutput                                 &timer);

    /**
     * The further load cases on the last mesh, after the first one was
     * solved with @p first_results; writes one result set per case,
     * load_cases.csv, load_cases.pvd and the load-case plot. Returns the
     * number of failed verification checks.
     */
    unsigned int
    run_load_cases(const Results<dim>                          &first_results,
                   const std::vector<std::vector<CycleRecord>> &sequences,
                   TimerOutput                                 &timer);

    std::ostream &
    log() const;

    /**
     * The results table on the terminal; in test mode also the pressure
     * profile of every interface.
     */
    void
    print_results(const Results<dim> &results) const;

    std::string scene_file;

    MeshInput<dim>          mesh_input;
    Materials<dim>          materials;
    BoundaryConditions<dim> boundary_conditions;
    ContactInterfaces       contact_interfaces;
    ActiveSetSolver         active_set_solver;
    LoadCases               load_cases;
    RigidMotions<dim>       motions;
    /** The load parameter of the case being solved (set_load_parameter()). */
    double            load_parameter = 0;
    OutputWriter<dim> output_writer;
    Verification<dim> verification;
    Refinement        refinement;

    Triangulation<dim> triangulation;
    /**
     * Where the run divides the mesh over its ranks (distribution_reason()):
     * each rank's cells; triangulation is then empty.
     */
    std::unique_ptr<DistributedMesh<dim>> distributed;
    /** Why (the solver's log line). */
    std::string distributed_reason;
    /**
     * The mesh phase's steps on this rank where the mesh may be distributed
     * [s, summed over the cycles]: "read" (rank 0 alone makes and checks
     * the whole mesh) and distribute_mesh()'s steps; summary.json's
     * wall_time as "mesh: <step>" (the scaling model's serial terms).
     */
    std::map<std::string, double> mesh_times;
    /**
     * This rank's peak resident set [MB] by the end of the last mesh it
     * distributed (rank 0: the whole mesh and a description at once;
     * summary.json's solver/mesh_peak_memory_MB), 0 if none.
     */
    double mesh_peak_MB = 0;
    /**
     * Rank 0: the memory check's estimate of the last distributed mesh's
     * run [MB], rank 0's and another rank's (estimated_distributed_bytes();
     * summary.json's solver/estimated_first_rank_MB, estimated_rank_MB), 0
     * if none.
     */
    double estimated_first_MB = 0, estimated_other_MB = 0;
    // FE_Q(1)^dim or FE_SimplexP(1)^dim, by the mesh's cells (make_mesh).
    std::unique_ptr<FiniteElement<dim>> fe;
    DoFHandler<dim>                     dof_handler;
    std::vector<unsigned int>           body_of_cell;
    unsigned int                        n_bodies = 0;
    std::vector<std::string>            body_names;

    /**
     * The error bars of the reported quantities, from the last sequence of
     * meshes (estimate_errors()); empty before the first solve.
     */
    std::map<std::string, ErrorEstimate> error_estimates;
    /**
     * Per reported peak pressure and contact force ("peak pressure",
     * "interface NAME: peak pressure", "interface NAME: force"): the
     * cells' shares of its goal-oriented estimate
     * (estimate_mesh_errors()), a refinement indicator that serves it.
     */
    std::map<std::string, Vector<float>> goal_indicators;

    /**
     * The error bars of this mesh alone. Goal-oriented (frictionless
     * contact): each interface's peak pressure and contact force, whose
     * influence (multiplier_influence() of the peak pair and its
     * neighbours, of all active pairs) weights the recovered strain errors
     * (recovered_error_products()), bar 1.5 |estimate| (a peak pressure's
     * at least its difference from its patch's mean); each contact length
     * (estimate_length_errors()) and each material's stress extremes
     * (estimate_stress_errors()). A bar of this mesh replaces the mesh
     * sequence's; where error_estimates already holds a bar from a
     * uniformly refined sequence (@p uniform), the larger of the two is
     * kept: the recovery does not see the error of curved boundaries
     * approximated by straight edges, the sequence does. Where the value
     * changed since the previous mesh by more than both meshes' bars allow
     * (@p previous: that mesh's estimates), the bars are not consistent
     * with the refinement (a quantity that does not converge there): the
     * bar is at least that change, flagged. Fills goal_indicators (the
     * peak pressures' and forces'). Returns the energy's eta^2 of the same
     * strain recovery (recovered_error_products() with the contact tractions
     * imposed; without contact rows or with friction the plain recovery).
     */
    double
    estimate_mesh_errors(const Results<dim>                         &results,
                         const bool                                  uniform,
                         const std::map<std::string, ErrorEstimate> &previous);

    /**
     * Each interface's contact length bar: one slave spacing at each edge
     * of the contact zone (the weights of an active slave vertex and an
     * inactive neighbour on a slave face), handed to @p keep.
     */
    void
    estimate_length_errors(
      const Results<dim>                                            &results,
      const std::function<void(const std::string &, ErrorEstimate)> &keep)
      const;

    /**
     * Each material's tau_yy min and max and von Mises max bars from the
     * strain recovery @p recovered of the solution, handed to @p keep.
     */
    void
    estimate_stress_errors(
      const Results<dim>                                            &results,
      const RecoveredStrain<dim>                                    &recovered,
      const std::function<void(const std::string &, ErrorEstimate)> &keep)
      const;

    /**
     * In target mode for a peak pressure or a contact force: its goal
     * indicator (the adaptive refinement serves it); else none (Kelly's).
     */
    const Vector<float> *
    goal_indicator() const
    {
      const auto found = goal_indicators.find(refinement.target_quantity);
      return refinement.target_error > 0 && found != goal_indicators.end()
               ? &found->second
               : nullptr;
    }

    AffineConstraints<double> constraints;
    ContactPairs<dim>         contact_pairs;
    /**
     * With friction: the normal, tangential and stick rows
     * (ContactPairs::solver_rows()), which the
     * contact system keeps a reference to (see rows_for_solver()).
     */
    std::vector<ContactRow> friction_rows;

    /**
     * With friction, along a load path: the gaps of the tangential rows
     * (and of the rows that hold sticking pairs) become the tangential
     * jumps of @p u, so that a pair sticks where it is; with @p offsets
     * (one per pair, a moved case) less t_j . offset, the pair's rigid
     * slip since (RigidMotions::relative_motion()): the slip of the case
     * counts it.
     */
    void
    hold_tangential_rows_at(const Vector<double>              &u,
                            const std::vector<Tensor<1, dim>> &offsets = {});

    /** The rows the contact system and the active-set loop see. */
    const std::vector<ContactRow> &
    rows_for_solver() const
    {
      return !contact_pairs.frictional() ? contact_pairs.rows : friction_rows;
    }
    /** The bodies' rigid motions on the dofs (setup_system()). */
    std::unique_ptr<RigidModes<dim>> rigid_modes;
    SparsityPattern                  sparsity_pattern;
    /**
     * On the distributed mesh: this rank's rows of every set's pattern
     * (made there: Trilinos's empty pattern already calls MPI, which a run
     * without mpirun, such as --print-parameters, has not started).
     */
    std::unique_ptr<TrilinosWrappers::SparsityPattern> distributed_pattern;
    SparseMatrix<double>                               system_matrix;
    Vector<double>                                     system_rhs;
    Vector<double>                                     displacement;
    ContactSolution                                    contact_solution;
    /** The path assemble_system() chose for the next contact system. */
    SolverPlan solver_plan;
    /** The last cycle's factorised system, kept for further load cases. */
    std::unique_ptr<ContactSystem> contact_system;
    /**
     * The last solve's solver figures for summary.json: phase times [s],
     * number of contact unknowns, reference solve (see ActiveSetSolver).
     */
    std::map<std::string, double> solver_figures;
    std::string                   solver_name;
    /** Positions and slave lengths of the last cycle's active pairs. */
    std::vector<std::pair<Point<dim>, double>> previous_contact;

    mutable std::ostringstream quiet;
  };
} // namespace knee_contact

#endif
