#ifndef knee_contact_contact_sides_h
#define knee_contact_contact_sides_h

#include <knee_contact/contact/contact.h>

#include <deal.II/base/point.h>
#include <deal.II/base/tensor.h>

#include <array>
#include <map>
#include <string>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * The two sides of one 2D contact interface as the contact
   * discretisations see them: the slave vertices with their averaged normals,
   * the slave faces, and the master faces. Collected once by
   * ContactInterfaces::make_pairs(); each discretisation (node-to-segment,
   * mortar) turns them into rows a_p x <= g_p, one per slave vertex.
   */
  struct ContactSides
  {
    struct SlaveVertex
    {
      Point<2> position;
      /** Sum of the outward normals of the vertex's faces, each with the
       * face's length as its norm: the length-weighted average direction. */
      Tensor<1, 2>                           normal;
      double                                 length = 0;
      std::array<types::global_dof_index, 2> dofs;

      Tensor<1, 2>
      unit_normal() const
      {
        return normal / normal.norm();
      }
    };

    struct Face
    {
      /** Vertex keys (into slaves for a slave face). */
      std::array<unsigned int, 2>                           vertex_keys;
      std::array<Point<2>, 2>                               vertices;
      std::array<std::array<types::global_dof_index, 2>, 2> dofs;
      /** Unit outward normal. */
      Tensor<1, 2> normal;
    };

    std::map<unsigned int, SlaveVertex> slaves;
    std::vector<Face>                   slave_faces;
    std::vector<Face>                   master_faces;
    /** The shortest slave face. */
    double min_length = 0;
  };



  /**
   * Node-to-segment rows: each slave vertex projected along its normal onto
   * the closest facing master face (the seed's node pairs when the meshes
   * match). Rows are not yet reduced by the constraints.
   */
  ContactPairs<2>
  node_to_segment_rows(const ContactSides     &sides,
                       const ContactInterface &interface,
                       const unsigned int      interface_index,
                       const std::string      &where);

  /**
   * Dual mortar rows (segment-to-segment, Wohlmuth's biorthogonal
   * multiplier basis on the slave side), one per slave vertex, normalised
   * so that they read like node-to-segment rows: the slave vertex's own
   * normal displacement minus a weighted mean of the master's, against the
   * weighted gap; ContactRow::length is the row's weight, so multiplier /
   * length is the multiplier's value there, a pressure [Pa].
   */
  ContactPairs<2>
  mortar_rows(const ContactSides     &sides,
              const ContactInterface &interface,
              const unsigned int      interface_index,
              const std::string      &where);
} // namespace knee_contact

#endif
