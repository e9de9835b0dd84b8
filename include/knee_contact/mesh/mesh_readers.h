#ifndef knee_contact_mesh_readers_h
#define knee_contact_mesh_readers_h

#include <deal.II/base/point.h>

#include <deal.II/grid/tria.h>

#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Mesh files other than Gmsh's, made safe before anything builds a mesh of
   * them, and the one step that turns triangles into quadrilaterals (and
   * tetrahedra into hexahedra) where the solver needs them. Every error names
   * the file and line.
   */
  namespace mesh_readers
  {
    /**
     * The linear elastic constants an Abaqus deck gives the cells of one
     * material id (*Solid Section, MATERIAL= and that *Material's
     * *Elastic), or why it gives none.
     */
    struct DeckMaterial
    {
      std::string name; // of the *Material
      double      youngs_modulus = 0;
      double      poissons_ratio = 0;
      std::string problem; // empty if the constants are given
    };

    /**
     * A coarse mesh as deal.II's create_triangulation takes it. The readers
     * of this file read 2D meshes, the Abaqus reader 3D ones too; other 3D
     * meshes come from Gmsh (MeshInput).
     */
    template <int dim = 2>
    struct Description
    {
      std::vector<Point<dim>>    vertices;
      std::vector<CellData<dim>> cells;
      SubCellData                subcells;
      /** Abaqus decks: by material id. */
      std::map<types::material_id, DeckMaterial> deck_materials;
    };

    /**
     * 3 if the Abaqus deck @p file (with the decks it includes) has 3D
     * solid elements (C3D...), else 2.
     */
    unsigned int
    abaqus_dimension(const std::string &file);

    /**
     * Read an Abaqus input deck (.inp): *Node, *Element (2D: CPS3, CPE3,
     * CPS4, CPE4; 3D: C3D4, C3D8; with their R/H/I variants), *Elset,
     * *Nset (with or without GENERATE), *Surface (TYPE=ELEMENT with faces
     * S1-S4, S1-S6 of hexahedra, or TYPE=NODE),
     * flat or as Abaqus/CAE writes it: *Part, *Assembly, *Instance (moved
     * by its translation and rotation lines), sets and surfaces of the
     * assembly over instances (INSTANCE= or INSTANCE.NAME), *Include,
     * continued lines. A part's set is INSTANCE.SET, or SET if one
     * instance has it. *Tie, *Contact Pair, rigid and shell definitions are
     * refused by name.
     * @p element_sets gives each element set its material id (empty: the
     * element sets of the *Solid Section lines in file order get 1, 2, ...);
     * @p boundary_sets gives a surface, node set or set of facet elements
     * (2D: lines, 3D: CPS/CPE/SFM3D triangles and quadrilaterals) its
     * boundary id (a boundary face whose nodes are all in a node set
     * belongs to it). Each material id's *Material constants are returned
     * in Description::deck_materials.
     * Written by hand: deal.II 9.4's read_abaqus reads quadrilaterals only,
     * takes ids only from names of the form EB<n>, Material-<n>, SS<n>,
     * and trusts numbering and counts.
     */
    template <int dim>
    Description<dim>
    read_abaqus(const std::string                         &file,
                const std::map<std::string, unsigned int> &element_sets,
                const std::map<std::string, unsigned int> &boundary_sets);

    /**
     * Read an AVS UCD file (.ucd, .inp of AVS is not accepted: .inp means
     * Abaqus here): nodes, then cells of type tri and quad (material id) and
     * line (boundary id); pt cells and data sections are ignored. Written by
     * hand: deal.II 9.4's read_ucd reads quadrilaterals only and trusts
     * counts and node numbers.
     */
    Description<2>
    read_ucd(const std::string &file);

    /**
     * Read a VTK XML unstructured grid (.vtu) of one piece: Points, Cells
     * (connectivity, offsets, types: vertices, lines, triangles,
     * quadrilaterals) and the ids of cells (material ids) and of lines
     * (boundary ids) from the first cell field of MaterialID, gmsh:physical,
     * CellEntityIds, medit:ref, with DataArrays in ascii, inline binary
     * (base64) or raw appended format, uncompressed or zlib-compressed, as
     * ParaView, VTK and meshio write them. Written by hand: deal.II 9.4's
     * read_vtu reads only the files deal.II itself wrote.
     */
    Description<2>
    read_vtu(const std::string &file);

    /**
     * Read a legacy VTK file (.vtk, DATASET UNSTRUCTURED_GRID) of the 4.2
     * layout (CELLS as counts and vertices) or the 5.1 layout (OFFSETS and
     * CONNECTIVITY, as VTK 9, ParaView 5.10 and meshio write it), ASCII or
     * BINARY (big-endian), points in float or double: vertices, lines,
     * triangles and quadrilaterals; the ids from the first cell field of
     * MaterialID, gmsh:physical, CellEntityIds, medit:ref (SCALARS or
     * FIELD arrays; other attributes, POINT_DATA and VTK 9's METADATA are
     * skipped). Written by hand: deal.II 9.4's GridIn::read_vtk reads ASCII
     * 4.2 files only and trusts their counts.
     */
    Description<2>
    read_vtk(const std::string &file);

    /**
     * Split every triangle into three quadrilaterals at its centroid and,
     * if there are triangles, every quadrilateral into four at its centre,
     * so that the mesh stays conforming: the fallback for mixed meshes and
     * for Mesh/Triangles = quadrilaterals. Edge midpoints of boundary ids in
     * @p circles (id: centre) are put on the circle.
     */
    void
    split_into_quadrilaterals(
      Description<2>                               &mesh,
      const std::map<types::boundary_id, Point<2>> &circles);

    /**
     * Split every tetrahedron into four hexahedra (one at each corner: the
     * corner, the midpoints of its three edges, the centroids of its three
     * faces and the cell's centroid; every face of the pieces is plane)
     * and, if a hexahedron has an edge of a tetrahedron, every hexahedron
     * into eight at its centre, so that the mesh stays conforming; the
     * boundary faces and edges with ids are split with them. The 3D
     * fallback for meshes of both kinds (deal.II 9.4 has no element for
     * tetrahedra and hexahedra in one mesh without an hp::FECollection) and
     * for tetrahedral meshes refined adaptively.
     */
    void
    split_into_hexahedra(Description<3> &mesh);
  } // namespace mesh_readers
} // namespace knee_contact

#endif
