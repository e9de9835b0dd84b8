#ifndef knee_contact_gmsh_input_h
#define knee_contact_gmsh_input_h

#include <knee_contact/mesh/mesh_readers.h>

#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace knee_contact
{
  /**
   * Gmsh files from other people, made safe before anything reads them:
   * deal.II's GridIn trusts its input (a version header that lies about the
   * body corrupts the heap; an absurd count allocates all memory), and the
   * gmsh program executes what a .geo asks for. Written by hand because no
   * library validates a .msh file or a .geo script.
   */
  namespace gmsh_input
  {
    /**
     * Split Mesh/Gmsh arguments into words and accept only options that
     * shape the mesh: -setnumber NAME NUMBER, -clscale, -clmin, -clmax,
     * -clcurv, -smooth with one number each. Anything else (-string runs
     * .geo code, -o writes files, ...) is refused with a one-line error.
     */
    std::vector<std::string>
    arguments(const std::string &text);

    /**
     * Refuse a .geo (and every file it includes) that calls programs or
     * touches files: SystemCall, NonBlockingSystemCall, OnelabRun, Solver.*
     * options, Merge, Save, Print, Printf into a file, CreateDir,
     * DeleteFile, RenameFile, Plugin. The error names the file and line.
     */
    void
    check_geo(const std::string &file);

    /**
     * What gmsh may take: Mesh/Gmsh time limit [s] and Mesh/Gmsh memory
     * limit [MB]; 0 MB is a quarter of the machine's memory available
     * (MemAvailable, the cgroup's limit; at least 256 MB), so that gmsh
     * cannot starve the solve of the mesh it makes (a solve takes 8 to 35
     * kB a cell, gmsh far less).
     */
    struct Limits
    {
      double seconds   = 300;
      double megabytes = 0;

      /** The address-space limit for gmsh [bytes]. */
      double
      memory_bytes() const;
    };

    /**
     * Mesh @p geo with gmsh (argument vector, no shell, time limit) into
     * @p msh (format 2.2); errors name gmsh and the file.
     */
    void
    mesh(const std::string              &geo,
         const std::string              &msh,
         const std::vector<std::string> &arguments,
         const Limits                   &limits);

    /** Whether @p file starts as a binary .msh (file-type 1). */
    bool
    is_binary_msh(const std::string &file);

    /**
     * Write the binary .msh @p binary_msh as the ASCII .msh 4.1 @p msh with
     * the gmsh program (argument vector, no shell, time limit): deal.II 9.4
     * reads binary .msh only through the Gmsh API, which Debian's build
     * lacks. The result is then checked like any .msh.
     */
    void
    convert(const std::string &binary_msh,
            const std::string &msh,
            const Limits      &limits);

    /**
     * Check the structure of an ASCII .msh file (version 2.2 or 4.1)
     * against its header: section order, counts against the file's size,
     * node tags unique and referenced nodes present, element types deal.II
     * reads (points, lines, triangles, quadrilaterals, tetrahedra,
     * hexahedra), finite coordinates, a physical group on every cell. The
     * error names the file, the line and what is wrong. Returns the
     * dimension of the cells: 3 if there are tetrahedra or hexahedra, else 2.
     */
    unsigned int
    check_msh(const std::string &file);

    /**
     * The nodes and the dimension of a Gmsh element of @p type, for the
     * types deal.II reads (linear ones: points 15, lines 1, triangles 2,
     * quadrilaterals 3, tetrahedra 4, hexahedra 5); {0, 0} for any other.
     * check_msh() and read_msh() share it.
     */
    std::pair<unsigned int, unsigned int>
    element_kind(const long long type);

    /**
     * The vertices, cells and boundary faces of the ASCII .msh text
     * @p text (a file check_msh() passed, or one_group_per_entity()'s text
     * of it), exactly as deal.II 9.4's
     * GridIn::read_msh(std::istream &) hands them to
     * Triangulation::create_triangulation(): vertices in the order of
     * $Nodes, a cell's material id and a face's boundary id its physical
     * group (0 without), the vertices of quadrilaterals and hexahedra in
     * deal.II's order, lines (and in 3D triangles and quadrilaterals) as
     * boundary faces, and GridIn's clean-up (a mesh of quadrilaterals or
     * hexahedra loses its unused vertices and has its cells ordered
     * consistently; inverted cells are turned over).
     * tests/unit/msh_read.cc compares the two on meshes of both versions.
     * Unlike GridIn it skips sections it does not read wherever they are,
     * and reads the parametric coordinates of a node by its entity's
     * dimension. Its errors say what is wrong, the caller names the file.
     */
    template <int dim>
    mesh_readers::Description<dim>
    read_msh(const std::string_view text);

    /**
     * The checked .msh @p msh (2.2 or 4.1) with every entity in one
     * physical group, as deal.II 9.4 reads it: of an entity's
     * groups the one the scene names (@p cell_ids for entities of the
     * cells' dimension @p mesh_dim, @p facet_ids for one dimension less),
     * or the first if it names none; an entity in two groups the scene
     * names is refused with a one-line error naming @p file, the entity and
     * its groups. Returns "" if no entity is in several groups.
     */
    std::string
    one_group_per_entity(const std::string            &msh,
                         const std::string            &file,
                         const unsigned int            mesh_dim,
                         const std::set<unsigned int> &cell_ids,
                         const std::set<unsigned int> &facet_ids);
  } // namespace gmsh_input
} // namespace knee_contact

#endif
