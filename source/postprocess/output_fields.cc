// The fields of a result set: solution.vtu (DataOut), the picture data
// (cells.npy in 2D, surface.npy in 3D) and the contact CSVs.
#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/postprocess/output.h>

#include <deal.II/base/mpi.h>

#include <deal.II/distributed/tria_base.h>
#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <iomanip>
#include <sstream>

namespace knee_contact
{
  namespace
  {
    // The stress components (2D: tau_xx, tau_yy, tau_xy; 3D: tau_xx,
    // tau_yy, tau_zz, tau_xy, tau_xz, tau_yz) and von Mises of each cell's
    // material, from the displacement gradient.
    template <int dim>
    class StressPostprocessor : public DataPostprocessor<dim>
    {
    public:
      StressPostprocessor(const Materials<dim> &materials)
        : materials(materials)
      {}

      void
      evaluate_vector_field(
        const DataPostprocessorInputs::Vector<dim> &inputs,
        std::vector<Vector<double>>                &computed) const override
      {
        const auto           cell     = inputs.template get_cell<dim>();
        const Material<dim> &material = materials[cell->material_id()];
        const auto           order    = components();
        for (unsigned int q = 0; q < computed.size(); ++q)
          {
            SymmetricTensor<2, dim> strain;
            for (unsigned int i = 0; i < dim; ++i)
              for (unsigned int j = i; j < dim; ++j)
                strain[i][j] = 0.5 * (inputs.solution_gradients[q][i][j] +
                                      inputs.solution_gradients[q][j][i]);
            const auto stress = material.stress(strain);
            for (unsigned int c = 0; c < order.size(); ++c)
              computed[q](c) = stress[order[c].first][order[c].second];
            computed[q](order.size()) = material.von_mises(stress);
          }
      }

      std::vector<std::string>
      get_names() const override
      {
        if constexpr (dim == 2)
          return {"stress_xx", "stress_yy", "stress_xy", "von_mises"};
        return {"stress_xx",
                "stress_yy",
                "stress_zz",
                "stress_xy",
                "stress_xz",
                "stress_yz",
                "von_mises"};
      }

      UpdateFlags
      get_needed_update_flags() const override
      {
        return update_gradients;
      }

    private:
      static std::vector<std::pair<unsigned int, unsigned int>>
      components()
      {
        if constexpr (dim == 2)
          return {{0, 0}, {1, 1}, {0, 1}};
        return {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {0, 2}, {1, 2}};
      }

      const Materials<dim> &materials;
    };

    // A NumPy .npy file (format 1.0, little-endian float32) of @p data with
    // @p n_columns columns.
    void
    write_npy(std::ostream             &out,
              const std::vector<float> &data,
              const unsigned int        n_columns)
    {
      std::string header = "{'descr': '<f4', 'fortran_order': False, "
                           "'shape': (" +
                           std::to_string(data.size() / n_columns) + ", " +
                           std::to_string(n_columns) + "), }";
      // Magic, version 1.0, header length; header padded with spaces and a
      // newline so that the data starts at a multiple of 64 bytes.
      const std::size_t total = 10 + header.size() + 1;
      header += std::string((64 - total % 64) % 64, ' ') + "\n";
      const std::uint16_t length = header.size();
      out.write("\x93NUMPY\x01\x00", 8);
      out.put(static_cast<char>(length & 0xff));
      out.put(static_cast<char>(length >> 8));
      out << header;
      static_assert(sizeof(float) == 4, "float32 expected");
      out.write(reinterpret_cast<const char *>(data.data()),
                data.size() * sizeof(float));
    }

    /**
     * DataOut that lets its field names out, for writing its patches piece
     * by piece with DataOutBase::write_vtu_main().
     */
    template <int dim>
    class PiecewiseDataOut : public DataOut<dim>
    {
    public:
      std::vector<std::string>
      dataset_names() const
      {
        return this->get_dataset_names();
      }

      auto
      nonscalar_data_ranges() const
      {
        return this->get_nonscalar_data_ranges();
      }
    };
  } // namespace



  template <int dim>
  void
  OutputWriter<dim>::write_vtu(const DoFHandler<dim>           &dof_handler,
                               const std::vector<unsigned int> &body_of_cell,
                               const Vector<double>            &solution,
                               const Materials<dim>            &materials,
                               const ContactPairs<dim>         &pairs,
                               const ContactSolution           &contact,
                               const Results<dim>              &results) const
  {
    PiecewiseDataOut<dim> data_out;
    data_out.attach_dof_handler(dof_handler);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector_field(dim,
                   DataComponentInterpretation::component_is_part_of_vector);
    data_out.add_data_vector(solution,
                             std::vector<std::string>(dim, "displacement"),
                             DataOut<dim>::type_dof_data,
                             vector_field);
    StressPostprocessor<dim> stress(materials);
    data_out.add_data_vector(solution, stress);

    // Contact pressure and active flag at the slave vertices, stored in the
    // first two components of a displacement-like vector (3D: the third is
    // unused).
    Vector<double> contact_field(dof_handler.n_dofs());
    for (unsigned int p = 0; p < pairs.size(); ++p)
      {
        contact_field(pairs.points[p].slave_dofs[0]) = results.pressure[p];
        contact_field(pairs.points[p].slave_dofs[1]) =
          contact.active[p] ? 1 : 0;
      }
    std::vector<std::string> contact_names{"contact_pressure",
                                           "contact_active"};
    if (dim == 3)
      contact_names.emplace_back("unused");
    data_out.add_data_vector(
      contact_field,
      contact_names,
      DataOut<dim>::type_dof_data,
      std::vector<DataComponentInterpretation::DataComponentInterpretation>(
        dim, DataComponentInterpretation::component_is_scalar));

    // With friction, at the slave vertices: 2D, the tangential traction
    // along t and the status (0 open, 1 stick, 2 slip) in one vector, this
    // case's and the accumulated slip in another; 3D, the tangential
    // traction and this case's slip as vectors (Cartesian), the status and
    // the accumulated slip in a third.
    std::array<Vector<double>, 3> friction_fields;
    if (contact.status.size() == pairs.size() &&
        contact.accumulated_slip.size() == pairs.size())
      {
        for (auto &field : friction_fields)
          field.reinit(dof_handler.n_dofs());
        auto &[traction_field, slip_field, state_field] = friction_fields;
        for (unsigned int p = 0; p < pairs.size(); ++p)
          {
            const auto  &dofs   = pairs.points[p].slave_dofs;
            const double length = pairs.rows[p].length;
            if constexpr (dim == 2)
              {
                traction_field(dofs[0]) = contact.lambda_t[p][0] / length;
                traction_field(dofs[1]) = static_cast<int>(contact.status[p]);
                slip_field(dofs[0])     = contact.slip[p][0];
                slip_field(dofs[1])     = contact.accumulated_slip[p];
              }
            else
              {
                const Tensor<1, dim> traction =
                  tangential_vector(pairs.points[p], contact.lambda_t[p]) /
                  length;
                const Tensor<1, dim> slip =
                  tangential_vector(pairs.points[p], contact.slip[p]);
                for (unsigned int d = 0; d < dim; ++d)
                  {
                    traction_field(dofs[d]) = traction[d];
                    slip_field(dofs[d])     = slip[d];
                  }
                state_field(dofs[0]) = static_cast<int>(contact.status[p]);
                state_field(dofs[1]) = contact.accumulated_slip[p];
              }
          }
        const auto scalars =
          std::vector<DataComponentInterpretation::DataComponentInterpretation>(
            dim, DataComponentInterpretation::component_is_scalar);
        if constexpr (dim == 2)
          {
            data_out.add_data_vector(
              traction_field,
              std::vector<std::string>{"tangential_traction",
                                       "friction_status"},
              DataOut<dim>::type_dof_data,
              scalars);
            data_out.add_data_vector(
              slip_field,
              std::vector<std::string>{"slip", "accumulated_slip"},
              DataOut<dim>::type_dof_data,
              scalars);
          }
        else
          {
            data_out.add_data_vector(
              traction_field,
              std::vector<std::string>(dim, "tangential_traction"),
              DataOut<dim>::type_dof_data,
              vector_field);
            data_out.add_data_vector(slip_field,
                                     std::vector<std::string>(dim, "slip"),
                                     DataOut<dim>::type_dof_data,
                                     vector_field);
            data_out.add_data_vector(
              state_field,
              std::vector<std::string>{"friction_status",
                                       "accumulated_slip",
                                       "unused"},
              DataOut<dim>::type_dof_data,
              scalars);
          }
      }

    Vector<float> material_id(body_of_cell.size()),
      body_id(body_of_cell.size());
    for (const auto &cell : dof_handler.active_cell_iterators())
      {
        material_id(cell->active_cell_index()) = cell->material_id();
        body_id(cell->active_cell_index()) =
          body_of_cell[cell->active_cell_index()];
      }
    data_out.add_data_vector(material_id, "material_id");
    data_out.add_data_vector(body_id, "body_id");
    // zlib's fastest level: the file is 10 % larger than at the default
    // level and written several times faster (at 4e5 dofs the default took
    // longer than the contact solve).
    DataOutBase::VtkFlags flags;
    flags.compression_level = DataOutBase::VtkFlags::best_speed;
    // DataOut's patches hold every cell's values (about 1 kB per
    // tetrahedron with these fields) and the writer a float copy of them:
    // at 3.4e6 cells the run's peak memory went from 6.4 to 11 GB while the
    // VTU was written (measured). So the cells go in pieces of at most
    // cells_per_piece, each its own <Piece> of the one file (as deal.II's
    // write_vtu_in_parallel writes a piece per process): the writer's
    // memory is that of one piece.
    //
    // Under mpirun every rank holds the solution, and building a piece
    // (DataOut's patches and zlib) is the output's time: on a whole mesh
    // piece i is built by rank i mod N, which sends its bytes to rank 0, the
    // one that writes the folder (no shared file system is assumed). The
    // number of pieces is a multiple of N, so every rank builds as many (7
    // pieces of 446 206 cells on two ranks took 5.5 s, 8 pieces 2.1 s); the
    // file is one solution.vtu, as on one process. On a distributed mesh
    // each rank builds the pieces of its own cells.
    const unsigned int ranks = parallel::n_ranks(), rank = parallel::rank();
    const unsigned int n_cells =
      dof_handler.get_triangulation().n_active_cells();
    // Each piece: its rank, and on that rank its first cell and the index
    // its cells stay below (this rank's cells between them).
    std::vector<unsigned int>                                      owner;
    std::vector<typename Triangulation<dim>::active_cell_iterator> first;
    std::vector<unsigned int>                                      end_index;
    if (dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
          &dof_handler.get_triangulation()) == nullptr)
      {
        const unsigned int n_pieces =
          (n_cells + std::size_t(cells_per_piece) * ranks - 1) /
          (std::size_t(cells_per_piece) * ranks) * ranks;
        const unsigned int per_piece = (n_cells + n_pieces - 1) / n_pieces;
        first.resize(n_pieces, dof_handler.get_triangulation().end());
        for (unsigned int piece = 0; piece < n_pieces; ++piece)
          {
            owner.push_back(piece % ranks);
            end_index.push_back(
              std::min<std::size_t>(n_cells,
                                    std::size_t(piece + 1) * per_piece));
          }
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->active_cell_index() % per_piece == 0)
            first[cell->active_cell_index() / per_piece] = cell;
      }
    else
      {
        std::vector<typename Triangulation<dim>::active_cell_iterator> own;
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            own.push_back(cell);
        // At least one piece a rank (perhaps empty: more ranks than cells).
        const unsigned int mine = std::max<std::size_t>(
          1, (own.size() + cells_per_piece - 1) / cells_per_piece);
        const std::vector<unsigned int> counts =
          Utilities::MPI::all_gather(parallel::communicator(), mine);
        // Each rank's k-th piece, rank by rank, then the (k+1)-th: rank 0
        // writes them in this order, so that the others build their next
        // piece while it writes (rank by rank, a rank's second piece waited
        // for rank 0's last: 18.6 s of VTU at 1e6 DoFs on two ranks).
        for (unsigned int k = 0;
             k < *std::max_element(counts.begin(), counts.end());
             ++k)
          for (unsigned int r = 0; r < ranks; ++r)
            {
              if (k >= counts[r])
                continue;
              owner.push_back(r);
              first.push_back(dof_handler.get_triangulation().end());
              end_index.push_back(0);
              if (r != rank)
                continue;
              const std::size_t begin = std::size_t(k) * cells_per_piece;
              if (begin < own.size())
                first.back() = own[begin];
              end_index.back() =
                begin + cells_per_piece < own.size()
                  ? own[begin + cells_per_piece]->active_cell_index()
                  : n_cells;
            }
      }
    const unsigned int n_pieces = owner.size();
    const auto build = [&](const unsigned int piece, std::ostream &out) {
      const unsigned int end = end_index[piece];
      if (first[piece] == dof_handler.get_triangulation().end())
        return; // more ranks than cells: an empty piece
      using cell_iterator = typename DataOut<dim>::cell_iterator;
      data_out.set_cell_selection(
        [&](const Triangulation<dim> &) -> cell_iterator {
          return first[piece];
        },
        [end](const Triangulation<dim> &triangulation,
              const cell_iterator      &cell) -> cell_iterator {
          typename Triangulation<dim>::active_cell_iterator next(cell);
          ++next;
          while (next != triangulation.end() && !next->is_locally_owned())
            ++next;
          if (next == triangulation.end() || next->active_cell_index() >= end)
            return triangulation.end();
          return next;
        });
      data_out.build_patches(elements::mapping(dof_handler));
      DataOutBase::write_vtu_main(data_out.get_patches(),
                                  data_out.dataset_names(),
                                  data_out.nonscalar_data_ranges(),
                                  flags,
                                  out);
    };
    if (rank != 0)
      {
        // A helper: its pieces' bytes, one message each (tag: the piece).
        for (unsigned int piece = 0; piece < n_pieces; ++piece)
          if (owner[piece] == rank)
            {
              std::ostringstream bytes;
              build(piece, bytes);
              const std::string text = bytes.str();
              AssertThrow(text.size() < std::size_t(INT_MAX),
                          ExcMessage("a VTU piece of over 2 GB: lower Output/"
                                     "Cells per VTU piece"));
              MPI_Send(text.data(),
                       int(text.size()),
                       MPI_CHAR,
                       0,
                       int(piece),
                       parallel::communicator());
            }
        return;
      }
    // Rank 0: the pieces in order, its own built here, the others'
    // received. If the file cannot be written, the pieces still to come
    // are received and dropped, so that no helper waits for ever.
    unsigned int next    = 0;
    const auto   receive = [&](const unsigned int piece) {
      MPI_Status status;
      MPI_Probe(int(owner[piece]),
                int(piece),
                parallel::communicator(),
                &status);
      int size = 0;
      MPI_Get_count(&status, MPI_CHAR, &size);
      std::string text(size, '\0');
      MPI_Recv(text.data(),
               size,
               MPI_CHAR,
               int(owner[piece]),
               int(piece),
               parallel::communicator(),
               MPI_STATUS_IGNORE);
      return text;
    };
    try
      {
        write_file("solution.vtu", [&](std::ostream &out) {
          DataOutBase::write_vtu_header(out, flags);
          for (; next < n_pieces; ++next)
            if (owner[next] == 0)
              build(next, out);
            else
              {
                const std::string text = receive(next);
                out.write(text.data(), text.size());
              }
          DataOutBase::write_vtu_footer(out);
        });
      }
    catch (...)
      {
        for (; next < n_pieces; ++next)
          if (owner[next] != 0)
            receive(next);
        throw;
      }
  }



  template <int dim>
  void
  OutputWriter<dim>::write_cells(const DoFHandler<dim>           &dof_handler,
                                 const std::vector<unsigned int> &body_of_cell,
                                 const Vector<double>            &solution,
                                 const Results<dim>              &results) const
  {
    std::vector<float> data;
    unsigned int       n_columns = 0;
    if constexpr (dim == 2)
      {
        // Binary (NumPy's .npy, float32, one row per cell: material id,
        // body id, then x, y, u_x, u_y, stress_yy at the four vertices
        // counter-clockwise; a triangle repeats its third vertex): the
        // picture script's input, smaller than the VTU and written in a
        // fraction of the time a text file takes.
        n_columns = 2 + 4 * 5;
        data.reserve(
          std::size_t(dof_handler.get_triangulation().n_active_cells()) *
          n_columns);
        for (const auto &cell : dof_handler.active_cell_iterators())
          if (cell->is_locally_owned())
            {
              data.push_back(cell->material_id());
              data.push_back(body_of_cell[cell->active_cell_index()]);
              // Counter-clockwise: deal.II's vertex order is 0 1 3 2 on a
              // quadrilateral, 0 1 2 on a triangle.
              const bool triangle = cell->n_vertices() == 3;
              for (const unsigned int v :
                   triangle ? std::array<unsigned int, 4>{{0, 1, 2, 2}}
                            : std::array<unsigned int, 4>{{0, 1, 3, 2}})
                {
                  data.push_back(cell->vertex(v)[0]);
                  data.push_back(cell->vertex(v)[1]);
                  data.push_back(solution(cell->vertex_dof_index(v, 0)));
                  data.push_back(solution(cell->vertex_dof_index(v, 1)));
                  data.push_back(
                    results.stress_yy_at(cell->active_cell_index(), v));
                }
            }
      }
    else
      {
        // 3D: the boundary faces, one row each: material id, body id, then
        // x, y, z, u_x, u_y, u_z and von Mises at the four vertices in a
        // ring (a triangle repeats its third vertex); what the 3D picture
        // draws.
        n_columns = 2 + 4 * 7;
        for (const auto &cell : dof_handler.active_cell_iterators())
          for (const unsigned int f : cell->face_indices())
            if (cell->is_locally_owned() && cell->face(f)->at_boundary())
              {
                data.push_back(cell->material_id());
                data.push_back(body_of_cell[cell->active_cell_index()]);
                const unsigned int n = cell->face(f)->n_vertices();
                for (const unsigned int k :
                     n == 3 ? std::array<unsigned int, 4>{{0, 1, 2, 2}}
                            : std::array<unsigned int, 4>{{0, 1, 3, 2}})
                  {
                    // The face's k-th vertex as the cell numbers it, for
                    // the cell's vertex stresses.
                    unsigned int v = 0;
                    for (const unsigned int c : cell->vertex_indices())
                      if (cell->vertex_index(c) ==
                          cell->face(f)->vertex_index(k))
                        v = c;
                    for (unsigned int d = 0; d < dim; ++d)
                      data.push_back(cell->vertex(v)[d]);
                    for (unsigned int d = 0; d < dim; ++d)
                      data.push_back(solution(cell->vertex_dof_index(v, d)));
                    data.push_back(
                      results.von_mises_at(cell->active_cell_index(), v));
                  }
              }
      }
    if (dynamic_cast<const dealii::parallel::TriangulationBase<dim> *>(
          &dof_handler.get_triangulation()) != nullptr)
      {
        // A distributed mesh: each rank's rows to rank 0, which writes them
        // (in rank order; the picture does not depend on the rows' order).
        const std::vector<std::vector<float>> all =
          Utilities::MPI::gather(parallel::communicator(), data, 0);
        if (!write_files)
          return;
        data.clear();
        for (const auto &rows : all)
          data.insert(data.end(), rows.begin(), rows.end());
      }
    const std::string name = dim == 2 ? "cells.npy" : "surface.npy";
    write_file(name,
               [&](std::ostream &out) { write_npy(out, data, n_columns); });
  }



  template <int dim>
  void
  OutputWriter<dim>::write_contact_csv(const ContactInterfaces &interfaces,
                                       const ContactPairs<dim> &pairs,
                                       const Vector<double>    &solution,
                                       const ContactSolution   &contact,
                                       const Results<dim>      &results) const
  {
    for (unsigned int i = 0; i < interfaces.interfaces().size(); ++i)
      {
        // Order the pairs along the interface by the coordinate it spans
        // most (3D: then by the second), and in 2D measure arc length
        // between slave vertices.
        std::vector<unsigned int> order;
        Point<dim>                lower, upper;
        for (unsigned int d = 0; d < dim; ++d)
          {
            lower[d] = 1e300;
            upper[d] = -1e300;
          }
        for (unsigned int p = 0; p < pairs.size(); ++p)
          if (pairs.rows[p].interface == i)
            {
              order.push_back(p);
              for (unsigned int d = 0; d < dim; ++d)
                {
                  lower[d] = std::min(lower[d], pairs.points[p].position[d]);
                  upper[d] = std::max(upper[d], pairs.points[p].position[d]);
                }
            }
        std::vector<unsigned int> axes(dim);
        for (unsigned int d = 0; d < dim; ++d)
          axes[d] = d;
        // The widest span first (ties: the lower axis, as before in 2D).
        std::stable_sort(axes.begin(), axes.end(), [&](unsigned a, unsigned b) {
          return upper[a] - lower[a] > upper[b] - lower[b];
        });
        std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) {
          const Point<dim> &x = pairs.points[a].position;
          const Point<dim> &y = pairs.points[b].position;
          if (dim == 2 || x[axes[0]] != y[axes[0]])
            return x[axes[0]] < y[axes[0]];
          return x[axes[1]] < y[axes[1]];
        });
        const std::string name = csv_file_name(interfaces.interfaces()[i].name);
        write_file(name, [&](std::ostream &out) {
          // The discretisation in every row, so that a CSV read on its
          // own says how its pressure was computed.
          // With friction: 2D, the tangent t of the tangential row (the
          // common normal's, ContactPoint::tangents), the tangential
          // traction lambda_t / length along t [Pa] (the force on the slave
          // is -lambda_t t), this case's slip t . (u_slave - u_master)
          // increment [m]; 3D, the tangential traction and this case's slip
          // as Cartesian vectors; then the slip accumulated along the load
          // path [m] and the status.
          const bool friction = contact.status.size() == pairs.size() &&
                                contact.accumulated_slip.size() == pairs.size();
          out << (dim == 2 ? "arc_length,x,y,n_x,n_y," : "x,y,z,n_x,n_y,n_z,")
              << "gap,jump,pressure,active,";
          if (friction)
            out << (dim == 2 ? "t_x,t_y,tangential_traction,slip,"
                             : "tangential_traction_x,tangential_traction_y,"
                               "tangential_traction_z,slip_x,slip_y,slip_z,")
                << "accumulated_slip,status,";
          // The row's weight l_p [m, m^2 in 3D] (pressure times weight is
          // the pair's force), so that a CSV integrates on its own.
          out << "weight,discretisation\n" << std::setprecision(10);
          double s = 0;
          for (unsigned int k = 0; k < order.size(); ++k)
            {
              const unsigned int       p     = order[k];
              const ContactPoint<dim> &point = pairs.points[p];
              const ContactRow        &row   = pairs.rows[p];
              if (k > 0)
                s +=
                  point.position.distance(pairs.points[order[k - 1]].position);
              if (dim == 2)
                out << s << ',';
              for (unsigned int d = 0; d < dim; ++d)
                out << point.position[d] << ',';
              for (unsigned int d = 0; d < dim; ++d)
                out << point.normal[d] << ',';
              out << row.gap << ',' << row.jump(solution) << ','
                  << results.pressure[p] << ',' << (contact.active[p] ? 1 : 0)
                  << ',';
              if (friction)
                {
                  if (dim == 2)
                    out << point.tangents[0][0] << ',' << point.tangents[0][1]
                        << ',' << contact.lambda_t[p][0] / row.length << ','
                        << contact.slip[p][0] << ',';
                  else
                    {
                      const Tensor<1, dim> traction =
                        tangential_vector(point, contact.lambda_t[p]) /
                        row.length;
                      const Tensor<1, dim> slip =
                        tangential_vector(point, contact.slip[p]);
                      for (unsigned int d = 0; d < dim; ++d)
                        out << traction[d] << ',';
                      for (unsigned int d = 0; d < dim; ++d)
                        out << slip[d] << ',';
                    }
                  out << contact.accumulated_slip[p] << ','
                      << status_name(contact.status[p]) << ',';
                }
              out << row.length << ','
                  << pairing_name(results.interfaces[i].pairing) << '\n';
            }
        });
      }
  }



#define KNEE_CONTACT_INSTANTIATE(dim)                 \
  template void OutputWriter<dim>::write_vtu(         \
    const DoFHandler<dim> &,                          \
    const std::vector<unsigned int> &,                \
    const Vector<double> &,                           \
    const Materials<dim> &,                           \
    const ContactPairs<dim> &,                        \
    const ContactSolution &,                          \
    const Results<dim> &) const;                      \
  template void OutputWriter<dim>::write_cells(       \
    const DoFHandler<dim> &,                          \
    const std::vector<unsigned int> &,                \
    const Vector<double> &,                           \
    const Results<dim> &) const;                      \
  template void OutputWriter<dim>::write_contact_csv( \
    const ContactInterfaces &,                        \
    const ContactPairs<dim> &,                        \
    const Vector<double> &,                           \
    const ContactSolution &,                          \
    const Results<dim> &) const;
  KNEE_CONTACT_INSTANTIATE(2)
  KNEE_CONTACT_INSTANTIATE(3)
#undef KNEE_CONTACT_INSTANTIATE
} // namespace knee_contact
