#include <knee_contact/physics/elements.h>
#include <knee_contact/core/external_program.h>
#include <knee_contact/core/input.h>
#include <knee_contact/postprocess/output.h>

#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>

namespace knee_contact
{
  namespace
  {
    // Write @p file; the whole folder is swapped in at the end
    // (ResultFolder), so a failed write only has to be reported.
    void
    write_checked(const std::string                         &file,
                  const std::string                         &shown,
                  const std::function<void(std::ostream &)> &write)
    {
      std::ofstream out(file);
      AssertThrow(out.good(),
                  ExcMessage("cannot write '" + shown +
                             "': " + std::strerror(errno)));
      try
        {
          write(out);
        }
      catch (const StandardExceptions::ExcIO &)
        {
          // DataOut checks its stream and throws ExcIO when a write fails
          // (a full disk); the stream's state and errno tell why below.
          out.setstate(std::ios::failbit);
        }
      out.close();
      AssertThrow(!out.fail(),
                  ExcMessage("writing '" + shown + "' failed: " +
                             (errno == ENOSPC ? std::string("no space left "
                                                            "on the device")
                                              : std::strerror(errno))));
    }



    // The picture scripts: beside the binary in the build tree
    // (<bin>/scripts), or under <prefix>/share/knee_contact/scripts when
    // installed; found through /proc/self/exe, so a moved or installed
    // build still draws pictures.
    std::string
    find_script(const std::string &name)
    {
      std::error_code             code;
      const std::filesystem::path binary =
        std::filesystem::read_symlink("/proc/self/exe", code);
      const std::filesystem::path bin = binary.parent_path();
      for (const auto &candidate :
           {bin / "scripts" / name,
            bin / ".." / "share" / "knee_contact" / "scripts" / name})
        if (std::filesystem::exists(candidate, code))
          return candidate.lexically_normal().string();
      return "";
    }
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
  } // namespace



  template <int dim>
  void
  OutputWriter<dim>::declare_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    prm.declare_entry("Folder",
                      "",
                      Patterns::Anything(),
                      "Folder for the results, relative to the working "
                      "directory; empty: output/<scene file's base name>.");
    prm.declare_entry("Deformation magnification",
                      "10",
                      Patterns::Double(0),
                      "Factor on the displacement in pictures of the "
                      "deformed mesh (the seed's Fig. 2 uses 10).");
    prm.declare_entry("Terminal",
                      "normal",
                      Patterns::Selection("normal|test"),
                      "normal: progress, timings and a results table; test: "
                      "only numbers that do not depend on the machine, for "
                      "ctest.");
    prm.declare_entry("Pictures",
                      "true",
                      Patterns::Bool(),
                      "Draw deformation.png, stress_yy.png and "
                      "contact_pressure.png (3D: von_mises.png, the deformed "
                      "surface from two views) with matplotlib (needs Write "
                      "files).");
    prm.declare_entry("Labels",
                      "",
                      Patterns::Anything(),
                      "Points labelled in deformation.png: 'name: x, y; ...' "
                      "[m], e.g. the seed's points 1-10 (3D: 'name: x, y, "
                      "z').");
    prm.declare_entry("Picture time limit",
                      "600",
                      Patterns::Double(1),
                      "Seconds the picture script may take before it is "
                      "stopped (the result set is then kept without "
                      "pictures, with a warning).");
    prm.declare_entry("Write files",
                      "true",
                      Patterns::Bool(),
                      "Write solution.vtu, contact CSVs and summary.json.");
    prm.leave_subsection();
  }



  template <int dim>
  void
  OutputWriter<dim>::parse_parameters(ParameterHandler  &prm,
                                 const std::string &scene_file)
  {
    prm.enter_subsection("Output");
    output_folder = prm.get("Folder");
    if (output_folder.empty())
      output_folder =
        "output/" + std::filesystem::path(scene_file).stem().string();
    magnification      = prm.get_double("Deformation magnification");
    terminal_test      = prm.get("Terminal") == "test";
    write_files        = prm.get_bool("Write files");
    pictures           = prm.get_bool("Pictures");
    picture_time_limit = prm.get_double("Picture time limit");
    for (const auto &[name, point] :
         input::split_named(prm.get("Labels"), "Output/Labels", "name: x, y"))
      labels.emplace_back(name,
                          input::to_point<dim>(point, "Output/Labels"));
    prm.leave_subsection();
  }



  template <int dim>
  void
  OutputWriter<dim>::prepare()
  {
    if (write_files)
      result_folder = std::make_unique<ResultFolder>(output_folder);
  }



  template <int dim>
  void
  OutputWriter<dim>::commit()
  {
    if (result_folder)
      result_folder->commit();
    result_folder.reset();
  }



  template <int dim>
  void
  OutputWriter<dim>::warn(const std::string &message)
  {
    std::cout << "warning: " << message << std::endl;
    warnings.push_back(message);
  }



  template <int dim>
  std::string
  OutputWriter<dim>::staging(const std::string &name) const
  {
    Assert(result_folder, ExcInternalError());
    return result_folder->staging() + "/" + subfolder + name;
  }



  template <int dim>
  std::string
  OutputWriter<dim>::final_path(const std::string &name) const
  {
    return output_folder + "/" + subfolder + name;
  }



  template <int dim>
  void
  OutputWriter<dim>::set_subfolder(const std::string &name)
  {
    subfolder.clear();
    if (!write_files)
      return;
    if (!name.empty())
      {
        std::error_code error;
        std::filesystem::create_directory(staging(name), error);
        AssertThrow(!error,
                    ExcMessage("cannot create the folder '" + final_path(name) +
                               "': " + error.message()));
        subfolder = name + "/";
      }
  }



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
    DataOut<dim> data_out;
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
    data_out.build_patches(elements::mapping(dof_handler));
    // zlib's fastest level: the file is 10 % larger than at the default
    // level and written several times faster (at 4e5 dofs the default took
    // longer than the contact solve).
    DataOutBase::VtkFlags flags;
    flags.compression_level = DataOutBase::VtkFlags::best_speed;
    data_out.set_flags(flags);
    write_checked(staging("solution.vtu"),
                  final_path("solution.vtu"),
                  [&](std::ostream &out) { data_out.write_vtu(out); });
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
                  results.vertex_stress_yy[cell->active_cell_index()][v]);
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
            if (cell->face(f)->at_boundary())
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
                      results.vertex_von_mises[cell->active_cell_index()][v]);
                  }
              }
      }
    const std::string name = dim == 2 ? "cells.npy" : "surface.npy";
    write_checked(staging(name), final_path(name), [&](std::ostream &out) {
      write_npy(out, data, n_columns);
    });
  }



  template <int dim>
  void
  OutputWriter<dim>::write_file(
    const std::string                         &name,
    const std::function<void(std::ostream &)> &write) const
  {
    write_checked(staging(name), final_path(name), write);
  }



  template <int dim>
  bool
  OutputWriter<dim>::run_script(const std::string &script_name,
                           std::string       &message) const
  {
    if (!write_files || !pictures)
      return true;
    const std::string script = find_script(script_name);
    if (script.empty())
      {
        message = "scripts/" + script_name +
                  " is neither beside the program nor in "
                  "share/knee_contact/scripts";
        return false;
      }
    // An argument vector, no shell: the folder name is data.
    const std::string   log    = staging("pictures.log");
    const ProgramResult result = run_program(
      {"/usr/bin/python3", script, result_folder->staging() + "/" + subfolder},
      log,
      picture_time_limit);
    std::filesystem::remove(log);
    if (result.exit_code == 0)
      return true;
    message = describe_failure(result,
                               "python3 " + script_name,
                               output_folder,
                               "Output/Picture time limit",
                               picture_time_limit);
    return false;
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
        // most, and measure arc length between slave vertices.
        // (2D: 3D has no contact rows yet.)
        std::vector<unsigned int> order;
        Point<2>                  lower(1e300, 1e300), upper(-1e300, -1e300);
        for (unsigned int p = 0; p < pairs.size(); ++p)
          if (pairs.rows[p].interface == i)
            {
              order.push_back(p);
              for (unsigned int d = 0; d < 2; ++d)
                {
                  lower[d] = std::min(lower[d], pairs.points[p].position[d]);
                  upper[d] = std::max(upper[d], pairs.points[p].position[d]);
                }
            }
        const unsigned int axis =
          (upper[0] - lower[0] >= upper[1] - lower[1]) ? 0 : 1;
        std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) {
          return pairs.points[a].position[axis] <
                 pairs.points[b].position[axis];
        });
        const std::string name = csv_file_name(interfaces.interfaces()[i].name);
        write_checked(staging(name), final_path(name), [&](std::ostream &out) {
          // The discretisation in every row, so that a CSV read on its
          // own says how its pressure was computed.
          out << "arc_length,x,y,n_x,n_y,gap,jump,pressure,active,"
                 "discretisation\n"
              << std::setprecision(10);
          double s = 0;
          for (unsigned int k = 0; k < order.size(); ++k)
            {
              const ContactPoint<dim> &point = pairs.points[order[k]];
              const ContactRow        &row   = pairs.rows[order[k]];
              if (k > 0)
                s += point.position.distance(
                  pairs.points[order[k - 1]].position);
              out << s << ',' << point.position[0] << ',' << point.position[1]
                  << ',' << point.normal[0] << ',' << point.normal[1] << ','
                  << row.gap << ',' << row.jump(solution) << ','
                  << results.pressure[order[k]] << ','
                  << (contact.active[order[k]] ? 1 : 0) << ','
                  << pairing_name(results.interfaces[i].pairing) << '\n';
            }
        });
      }
  }



  template <int dim>
  void
  OutputWriter<dim>::write_summary(
    const Results<dim>                  &results,
    const ContactSolution               &contact,
    const Materials<dim>                &materials,
    const std::map<std::string, double> &wall_times,
    const std::string                   &solver,
    const std::map<std::string, double> &solver_figures) const
  {
    using json = nlohmann::ordered_json;
    json summary;
    summary["n_dofs"]               = results.n_dofs;
    summary["n_cells"]              = results.n_cells;
    summary["n_bodies"]             = results.n_bodies;
    summary["elements"]             = results.elements;
    const auto vector = [](const auto &v) {
      std::vector<double> components(dim);
      for (unsigned int d = 0; d < dim; ++d)
        components[d] = v[d];
      return components;
    };
    summary["dimension"]            = dim;
    summary["applied_load"]         = vector(results.applied_load);
    summary["equilibrium_residual"] = results.equilibrium_residual;
    summary["energy"]               = results.energy;
    summary["max_displacement"]     = results.max_displacement;
    for (const auto &[id, reaction] : results.reactions)
      summary["reactions"][std::to_string(id)] = vector(reaction);
    for (const auto &[id, range] : results.stress_yy_range)
      summary["stress_yy"][materials[id].name] = {{"material_id", id},
                                                  {"min", range.first},
                                                  {"max", range.second}};
    for (const auto &[id, value] : results.von_mises_max)
      summary["von_mises_max"][materials[id].name] = {{"material_id", id},
                                                      {"max", value}};
    unsigned int n_pairs = 0, n_active = 0;
    for (const auto &i : results.interfaces)
      {
        n_pairs += i.n_pairs;
        n_active += i.n_active;
        summary["contact_interfaces"][i.name] = {
          {"discretisation", pairing_name(i.pairing)},
          {"n_pairs", i.n_pairs},
          {"n_active", i.n_active},
          {"force", i.force},
          {"force_on_slave", vector(i.force_on_slave)},
          {"max_pressure", i.max_pressure},
          {"contact_length", i.contact_length}};
      }
    summary["n_contact_pairs"]       = n_pairs;
    summary["n_active_pairs"]        = n_active;
    summary["active_set_iterations"] = contact.n_iterations;
    summary["converged"]             = contact.converged;
    summary["max_penetration"]       = contact.max_penetration;
    summary["relative_max_penetration"] =
      results.max_displacement > 0
        ? contact.max_penetration / results.max_displacement
        : 0.;
    summary["complementarity_residual"]  = contact.complementarity;
    summary["deformation_magnification"] = magnification;
    for (const auto &[name, point] : labels)
      summary["labels"][name] = vector(point);
    if (!contact.converged)
      summary["failure"] = contact.failure;
    if (!warnings.empty())
      summary["warnings"] = warnings;
    for (const auto &[phase, seconds] : wall_times)
      summary["wall_time"][phase] = seconds;
    summary["solver"]["name"] = solver;
    for (const auto &[name, value] : solver_figures)
      summary["solver"][name] = value;
    write_checked(staging("summary.json"),
                  final_path("summary.json"),
                  [&](std::ostream &out) { out << summary.dump(2) << '\n'; });
  }


  template class OutputWriter<2>;
  template class OutputWriter<3>;
} // namespace knee_contact
