#ifndef knee_contact_mesh_h
#define knee_contact_mesh_h

#include <knee_contact/mesh/mesh_readers.h>

#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <deal.II/grid/tria.h>

#include <array>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The dimension of the scene @p scene_file: 3 if its mesh file has
   * volume cells (tetrahedra, hexahedra; a .geo is meshed to find out, and
   * the mesh is kept for MeshInput to read), else 2. Errors of the mesh
   * file are thrown here, as MeshInput would.
   */
  template <int dim>
  class MeshInput;

  /**
   * @p mesh_input holds the Mesh subsection as the scene wrote it (bound by
   * MeshInput::add_parameters() and parsed, nothing checked yet).
   */
  unsigned int
  scene_dimension(const MeshInput<2> &mesh_input,
                  const std::string  &scene_file);

  /**
   * The mesh scene_dimension() kept, let go (its temporary file removed)
   * where no rank will read it again: a run on the distributed mesh, whose
   * rank 0 read it alone.
   */
  void
  release_scene_mesh();



  /**
   * One Triangulation<dim> holding all bodies: read from a mesh file (Gmsh
   * .msh or .geo, which the gmsh program meshes first; Abaqus .inp; in 2D
   * also VTK .vtk/.vtu, UCD) or generated from rectangles (2D). Physical
   * surfaces (2D) or volumes (3D) are material ids, physical curves (2D) or
   * surfaces (3D) boundary ids. Bodies that share vertices are bonded;
   * bodies in contact must have distinct (possibly coincident) vertices on
   * their interface.
   */
  template <int dim>
  class MeshInput
  {
  public:
    /**
     * Declare the Mesh subsection, each entry bound to the member it sets.
     */
    void
    add_parameters(ParameterHandler &prm);

    /**
     * After parsing: resolve the file against @p scene_file and check what
     * the patterns cannot (sets named twice, rectangles' corners, the
     * centres' dimension, the file's existence).
     */
    void
    check_parameters(const std::string &scene_file);

    /**
     * The material ids and boundary ids the scene names (Materials,
     * conditions, interfaces): of an entity of a Gmsh file in several
     * physical groups, the one named is read.
     */
    void
    set_scene_ids(const std::set<types::material_id> &material_ids,
                  const std::set<types::boundary_id> &boundary_ids)
    {
      scene_material_ids = material_ids;
      scene_boundary_ids = boundary_ids;
      for (const auto &[id, centre] : circular_boundaries)
        scene_boundary_ids.insert(id);
    }

    /**
     * Build the coarse mesh, attach the circular manifolds and refine
     * globally as asked. @p distributed: the mesh is made on rank 0 to be
     * divided over the ranks (its memory check counts the distributed run's,
     * check_run_fits()).
     */
    void
    create(Triangulation<dim> &triangulation,
           const int           level       = 0,
           const bool          distributed = false) const;

    /**
     * Whether refinement cycles remesh instead of refining @p triangulation:
     * for tetrahedra from a .geo, gmsh meshes it anew at half the size per
     * level (create() with level > 0), since deal.II 9.4's refinement of
     * tetrahedra degrades them.
     */
    bool
    remeshes(const Triangulation<dim> &triangulation) const;

    /** Whether the mesh is a .geo that gmsh meshes (at any size). */
    bool
    from_geo() const;

    /**
     * Refuse, naming Contact/Coarse start levels, @p levels coarser meshes
     * that create() cannot make (level -levels): a .geo can be meshed
     * coarser by gmsh, other meshes have Global refinements to leave out.
     */
    void
    check_coarser_levels(const unsigned int levels) const;

    /**
     * The elastic constants the Abaqus deck Mesh/File gives each material
     * id (*Solid Section, *Material, *Elastic), for Materials/Elastic
     * constants = mesh file; refused for other files. The deck is read
     * once: create() takes the mesh read here.
     */
    std::map<types::material_id, mesh_readers::DeckMaterial>
    deck_materials() const;

  private:
    /** The Abaqus deck deck_materials() read, until create() takes it. */
    mutable std::unique_ptr<mesh_readers::Description<dim>> read_deck;

    struct Rectangle
    {
      Point<2>                          lower, upper;
      unsigned int                      n_x = 1, n_y = 1;
      types::material_id                material_id = 0;
      unsigned int                      group       = 0;
      std::array<types::boundary_id, 4> boundary_ids{}; // left right bottom top
    };

    /**
     * Read Mesh/File by its extension; split triangles into quadrilaterals
     * where the solver needs them (mixed meshes, Triangles =
     * quadrilaterals, adaptive refinement).
     */
    void
    read_file(Triangulation<dim> &triangulation, const int level) const;

    /**
     * The Gmsh mesh at refinement @p level (see remeshes()), read as
     * deal.II's GridIn reads it (gmsh_input::read_msh()) into
     * @p triangulation.
     */
    void
    read_gmsh(const int level, Triangulation<dim> &triangulation) const;

    /**
     * Whether a mesh of simplices (@p simplices) and other cells
     * (@p others) must be split into quadrilaterals or hexahedra (see
     * read_file).
     */
    bool
    needs_split(const bool simplices, const bool others) const;

    /** The same for the cells of @p triangulation. */
    bool
    needs_split(const Triangulation<dim> &triangulation) const;

    /**
     * Whether a cell of @p triangulation has a negative measure (its
     * vertices listed the wrong way round).
     */
    static bool
    any_cell_inverted(const Triangulation<dim> &triangulation);

    /**
     * Split @p mesh's triangles where needed (see read_file) and make
     * @p triangulation of it.
     */
    void
    finish(mesh_readers::Description<dim> &mesh,
           Triangulation<dim>             &triangulation) const;

    /** Source = rectangles (2D only: scene_dimension() gives 2). */
    void
    make_rectangles(Triangulation<dim> &triangulation) const;

    void
    make_rectangles_2d(Triangulation<2> &triangulation) const;

    /** Attach a PolarManifold (2D) or SphericalManifold (3D) to every id of
     * circular_boundaries. */
    void
    attach_manifolds(Triangulation<dim> &triangulation) const;

    enum class Source
    {
      rectangles,
      file
    };

    /**
     * The entries that become other members in check_parameters(), as the
     * scene wrote them.
     */
    struct Entries
    {
      std::string                                       file;
      std::string                                       gmsh_arguments;
      std::vector<std::pair<std::string, unsigned int>> abaqus_element_sets;
      std::vector<std::pair<std::string, unsigned int>> abaqus_boundary_sets;
      // x0, y0, x1, y1, n_x, n_y, material id, group, left, right, bottom
      // and top boundary ids.
      std::vector<std::tuple<double,
                             double,
                             double,
                             double,
                             unsigned int,
                             unsigned int,
                             unsigned int,
                             unsigned int,
                             unsigned int,
                             unsigned int,
                             unsigned int,
                             unsigned int>>
        rectangles{{0, 0, 1, 1, 1, 1, 1, 0, 1, 2, 3, 4}};
      std::vector<std::pair<unsigned int, std::vector<double>>>
        circular_boundaries;
    } entries;

    friend unsigned int
    scene_dimension(const MeshInput<2> &mesh_input,
                    const std::string  &scene_file);

    std::set<types::material_id>             scene_material_ids;
    std::set<types::boundary_id>             scene_boundary_ids;
    Source                                   source = Source::rectangles;
    std::string                              file;
    std::vector<std::string>                 gmsh_arguments;
    double                                   gmsh_time_limit   = 300;
    double                                   gmsh_memory_limit = 0;
    std::vector<Rectangle>                   rectangles;
    double                                   rotation_degrees = 0;
    unsigned int                             n_refinements    = 0;
    std::map<types::boundary_id, Point<dim>> circular_boundaries;
    bool                                     split_triangles = false;
    enum class RectangleCells
    {
      quadrilaterals,
      triangles,
      mixed
    } rectangle_cells = RectangleCells::quadrilaterals;
    std::map<std::string, unsigned int> abaqus_element_sets;
    std::map<std::string, unsigned int> abaqus_boundary_sets;

  public:
    /**
     * Set when the scene refines adaptively: deal.II 9.4's Kelly estimator
     * cannot integrate over the hanging faces of triangles, so a triangle
     * mesh is then split into quadrilaterals.
     */
    bool adaptive = false;
  };



  /**
   * The body of each active cell (index by active_cell_index()): bodies are
   * the connected sets of cells that share vertices. Numbered 0, 1, ... in the
   * order of their first cell, so numbering is deterministic.
   */
  template <int dim>
  std::vector<unsigned int>
  compute_body_ids(const Triangulation<dim> &triangulation,
                   unsigned int             &n_bodies);
  /**
   * Refuse a mesh with an inverted, degenerate or non-convex cell, with the
   * cell's place (on the coarse mesh and after every refinement).
   */
  template <int dim>
  void
  check_cells(const Triangulation<dim> &triangulation);

  /**
   * The memory a run on @p n_cells cells in @p dim dimensions needs on the
   * cheaper of its solver paths [bytes]: matrix, factorisation or AMG
   * hierarchy and vectors, measured (see mesh.cc). In 3D, @p tetrahedra:
   * the cells are hexahedra of twice the vertices of a tetrahedral mesh.
   */
  double
  estimated_run_bytes(unsigned int dim,
                      double       n_cells,
                      bool         tetrahedra = false);

  /**
   * The same for a run whose mesh rank 0 makes whole and divides over the
   * run's N ranks (the distributed mesh: the iterative path), per rank:
   * @p first rank 0's (the whole mesh and its part, or its share of the
   * run after), @p other every other rank's share.
   */
  void
  estimated_distributed_bytes(double  n_cells,
                              bool    tetrahedra,
                              double &first,
                              double &other);

  /**
   * Refuse, before anything of the size is allocated, a mesh of @p n_cells
   * cells that the memory available to the process (memory::available())
   * cannot hold: "<what>: about N cells need about X GB; Y GB are
   * available (MemAvailable)". @p what names the file and line or the
   * parameter that asks for the size. @p distributed: rank 0 makes the
   * mesh to divide it (estimated_distributed_bytes()); the ranks of a
   * machine share its memory by what each holds, not equally.
   */
  void
  check_run_fits(unsigned int       dim,
                 double             n_cells,
                 const std::string &what,
                 bool               tetrahedra  = false,
                 bool               distributed = false);
} // namespace knee_contact

#endif
