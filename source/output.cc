#include <knee_contact/input.h>
#include <knee_contact/output.h>

#include <deal.II/numerics/data_out.h>
#include <deal.II/numerics/data_postprocessor.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>

namespace knee_contact
{
  namespace
  {
    // Write through a temporary file and rename it over @p file.
    void
    write_atomically(const std::string                         &file,
                     const std::function<void(std::ostream &)> &write)
    {
      const std::string temporary = file + ".part";
      {
        std::ofstream out(temporary);
        AssertThrow(out.good(), ExcMessage("cannot write '" + temporary + "'"));
        write(out);
        out.flush();
        AssertThrow(out.good(),
                    ExcMessage("writing '" + temporary + "' failed"));
      }
      std::filesystem::rename(temporary, file);
    }

    // tau_xx, tau_yy, tau_xy and von Mises of each cell's material, from the
    // displacement gradient.
    class StressPostprocessor : public DataPostprocessor<2>
    {
    public:
      StressPostprocessor(const Materials &materials)
        : materials(materials)
      {}

      void
      evaluate_vector_field(
        const DataPostprocessorInputs::Vector<2> &inputs,
        std::vector<Vector<double>>              &computed) const override
      {
        const auto      cell     = inputs.template get_cell<2>();
        const Material &material = materials[cell->material_id()];
        for (unsigned int q = 0; q < computed.size(); ++q)
          {
            SymmetricTensor<2, 2> strain;
            for (unsigned int i = 0; i < 2; ++i)
              for (unsigned int j = i; j < 2; ++j)
                strain[i][j] = 0.5 * (inputs.solution_gradients[q][i][j] +
                                      inputs.solution_gradients[q][j][i]);
            const auto stress = material.stress(strain);
            computed[q](0)    = stress[0][0];
            computed[q](1)    = stress[1][1];
            computed[q](2)    = stress[0][1];
            computed[q](3)    = material.von_mises(stress);
          }
      }

      std::vector<std::string>
      get_names() const override
      {
        return {"stress_xx", "stress_yy", "stress_xy", "von_mises"};
      }

      UpdateFlags
      get_needed_update_flags() const override
      {
        return update_gradients;
      }

    private:
      const Materials &materials;
    };
  } // namespace



  void
  OutputWriter::declare_parameters(ParameterHandler &prm)
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
                      "contact_pressure.png with matplotlib (needs Write "
                      "files).");
    prm.declare_entry("Labels",
                      "",
                      Patterns::Anything(),
                      "Points labelled in deformation.png: 'name: x, y; ...' "
                      "[m], e.g. the seed's points 1-10.");
    prm.declare_entry("Write files",
                      "true",
                      Patterns::Bool(),
                      "Write solution.vtu, contact CSVs and summary.json.");
    prm.leave_subsection();
  }



  void
  OutputWriter::parse_parameters(ParameterHandler  &prm,
                                 const std::string &scene_file)
  {
    prm.enter_subsection("Output");
    output_folder = prm.get("Folder");
    if (output_folder.empty())
      output_folder =
        "output/" + std::filesystem::path(scene_file).stem().string();
    magnification = prm.get_double("Deformation magnification");
    terminal_test = prm.get("Terminal") == "test";
    write_files   = prm.get_bool("Write files");
    pictures      = prm.get_bool("Pictures");
    for (const auto &[name, point] :
         input::split_named(prm.get("Labels"), "Output/Labels", "name: x, y"))
      labels.emplace_back(name, input::to_point(point, "Output/Labels"));
    prm.leave_subsection();
  }



  void
  OutputWriter::prepare() const
  {
    if (!write_files)
      return;
    std::error_code error;
    std::filesystem::create_directories(output_folder, error);
    const std::string probe = output_folder + "/.write_test";
    AssertThrow(!error && std::ofstream(probe).good(),
                ExcMessage("Output/Folder: cannot write to '" + output_folder +
                           "'"));
    std::filesystem::remove(probe);
  }



  void
  OutputWriter::write_vtu(const DoFHandler<2>             &dof_handler,
                          const std::vector<unsigned int> &body_of_cell,
                          const Vector<double>            &solution,
                          const Materials                 &materials,
                          const std::vector<ContactPair>  &pairs,
                          const ContactSolution           &contact,
                          const Results                   &results) const
  {
    DataOut<2> data_out;
    data_out.attach_dof_handler(dof_handler);
    const std::vector<DataComponentInterpretation::DataComponentInterpretation>
      vector_field(2, DataComponentInterpretation::component_is_part_of_vector);
    data_out.add_data_vector(solution,
                             std::vector<std::string>(2, "displacement"),
                             DataOut<2>::type_dof_data,
                             vector_field);
    StressPostprocessor stress(materials);
    data_out.add_data_vector(solution, stress);

    // Contact pressure and active flag at the slave vertices, stored in the
    // two components of a displacement-like vector.
    Vector<double> contact_field(dof_handler.n_dofs());
    for (unsigned int p = 0; p < pairs.size(); ++p)
      {
        contact_field(pairs[p].slave_dofs[0]) = results.pressure[p];
        contact_field(pairs[p].slave_dofs[1]) = contact.active[p] ? 1 : 0;
      }
    data_out.add_data_vector(
      contact_field,
      std::vector<std::string>{"contact_pressure", "contact_active"},
      DataOut<2>::type_dof_data,
      std::vector<DataComponentInterpretation::DataComponentInterpretation>(
        2, DataComponentInterpretation::component_is_scalar));

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
    data_out.build_patches();
    write_atomically(output_folder + "/solution.vtu",
                     [&](std::ostream &out) { data_out.write_vtu(out); });
  }



  void
  OutputWriter::write_cells(const DoFHandler<2>             &dof_handler,
                            const std::vector<unsigned int> &body_of_cell,
                            const Vector<double>            &solution,
                            const Results                   &results) const
  {
    write_atomically(output_folder + "/cells.csv", [&](std::ostream &out) {
      out << "material_id,body_id";
      for (unsigned int v = 0; v < 4; ++v)
        for (const char *name : {"x", "y", "u_x", "u_y", "stress_yy"})
          out << ',' << name << v;
      out << '\n' << std::setprecision(9);
      for (const auto &cell : dof_handler.active_cell_iterators())
        {
          out << static_cast<unsigned int>(cell->material_id()) << ','
              << body_of_cell[cell->active_cell_index()];
          // Counter-clockwise: deal.II's vertex order is 0 1 3 2.
          for (const unsigned int v : {0u, 1u, 3u, 2u})
            out << ',' << cell->vertex(v)[0] << ',' << cell->vertex(v)[1] << ','
                << solution(cell->vertex_dof_index(v, 0)) << ','
                << solution(cell->vertex_dof_index(v, 1)) << ','
                << results.vertex_stress_yy[cell->active_cell_index()][v];
          out << '\n';
        }
    });
  }



  void
  OutputWriter::write_file(
    const std::string                         &name,
    const std::function<void(std::ostream &)> &write) const
  {
    write_atomically(output_folder + "/" + name, write);
  }



  bool
  OutputWriter::run_script(const std::string &script_name,
                           std::string       &message) const
  {
    if (!write_files || !pictures)
      return true;
    const std::string script =
      std::string(KNEE_CONTACT_SOURCE_DIR) + "/scripts/" + script_name;
    const std::string log     = output_folder + "/pictures.log";
    const std::string command = "/usr/bin/python3 '" + script + "' '" +
                                output_folder + "' > '" + log + "' 2>&1";
    if (std::system(command.c_str()) == 0)
      {
        std::filesystem::remove(log);
        return true;
      }
    std::ifstream in(log);
    std::string   line;
    while (std::getline(in, line))
      message = line;
    return false;
  }



  void
  OutputWriter::write_contact_csv(const ContactInterfaces        &interfaces,
                                  const std::vector<ContactPair> &pairs,
                                  const Vector<double>           &solution,
                                  const ContactSolution          &contact,
                                  const Results                  &results) const
  {
    for (unsigned int i = 0; i < interfaces.interfaces().size(); ++i)
      {
        // Order the pairs along the interface by the coordinate it spans
        // most, and measure arc length between slave vertices.
        std::vector<unsigned int> order;
        Point<2>                  lower(1e300, 1e300), upper(-1e300, -1e300);
        for (unsigned int p = 0; p < pairs.size(); ++p)
          if (pairs[p].interface == i)
            {
              order.push_back(p);
              for (unsigned int d = 0; d < 2; ++d)
                {
                  lower[d] = std::min(lower[d], pairs[p].position[d]);
                  upper[d] = std::max(upper[d], pairs[p].position[d]);
                }
            }
        const unsigned int axis =
          (upper[0] - lower[0] >= upper[1] - lower[1]) ? 0 : 1;
        std::sort(order.begin(), order.end(), [&](unsigned a, unsigned b) {
          return pairs[a].position[axis] < pairs[b].position[axis];
        });
        std::string name = interfaces.interfaces()[i].name;
        std::replace_if(
          name.begin(),
          name.end(),
          [](const char c) { return !std::isalnum(c) && c != '-'; },
          '_');
        write_atomically(
          output_folder + "/contact_" + name + ".csv", [&](std::ostream &out) {
            out << "arc_length,x,y,n_x,n_y,gap,jump,pressure,active\n"
                << std::setprecision(10);
            double s = 0;
            for (unsigned int k = 0; k < order.size(); ++k)
              {
                const ContactPair &pair = pairs[order[k]];
                if (k > 0)
                  s += pair.position.distance(pairs[order[k - 1]].position);
                out << s << ',' << pair.position[0] << ',' << pair.position[1]
                    << ',' << pair.normal[0] << ',' << pair.normal[1] << ','
                    << pair.gap << ',' << pair.jump(solution) << ','
                    << results.pressure[order[k]] << ','
                    << (contact.active[order[k]] ? 1 : 0) << '\n';
              }
          });
      }
  }



  void
  OutputWriter::write_summary(
    const Results                       &results,
    const ContactSolution               &contact,
    const Materials                     &materials,
    const std::map<std::string, double> &wall_times) const
  {
    using json = nlohmann::ordered_json;
    json summary;
    summary["n_dofs"]               = results.n_dofs;
    summary["n_cells"]              = results.n_cells;
    summary["n_bodies"]             = results.n_bodies;
    summary["applied_load"]         = {results.applied_load[0],
                                       results.applied_load[1]};
    summary["equilibrium_residual"] = results.equilibrium_residual;
    summary["energy"]               = results.energy;
    summary["max_displacement"]     = results.max_displacement;
    for (const auto &[id, reaction] : results.reactions)
      summary["reactions"][std::to_string(id)] = {reaction[0], reaction[1]};
    for (const auto &[id, range] : results.stress_yy_range)
      summary["stress_yy"][materials[id].name] = {{"material_id", id},
                                                  {"min", range.first},
                                                  {"max", range.second}};
    unsigned int n_pairs = 0, n_active = 0;
    for (const auto &i : results.interfaces)
      {
        n_pairs += i.n_pairs;
        n_active += i.n_active;
        summary["contact_interfaces"][i.name] = {
          {"n_pairs", i.n_pairs},
          {"n_active", i.n_active},
          {"force", i.force},
          {"force_on_slave", {i.force_on_slave[0], i.force_on_slave[1]}},
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
      summary["labels"][name] = {point[0], point[1]};
    if (!contact.converged)
      summary["failure"] = contact.failure;
    for (const auto &[phase, seconds] : wall_times)
      summary["wall_time"][phase] = seconds;
    write_atomically(output_folder + "/summary.json", [&](std::ostream &out) {
      out << summary.dump(2) << '\n';
    });
  }
} // namespace knee_contact
