#include <knee_contact/base/external_program.h>
#include <knee_contact/base/input.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/physics/elements.h>
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
  } // namespace



  template <int dim>
  void
  OutputWriter<dim>::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Output");
    prm.add_parameter("Folder",
                      output_folder,
                      "Folder for the results, relative to the working "
                      "directory; empty: output/<scene file's base name>.",
                      Patterns::DirectoryName());
    prm.add_parameter("Deformation magnification",
                      magnification,
                      "Factor on the displacement in pictures of the "
                      "deformed mesh (the seed's Fig. 2 uses 10).",
                      Patterns::Double(0));
    input::add_selection(prm,
                         "Terminal",
                         terminal_test,
                         {{"normal", false}, {"test", true}},
                         "normal: progress, timings and a results table; "
                         "test: only numbers that do not depend on the "
                         "machine, for ctest.");
    prm.add_parameter("Pictures",
                      pictures,
                      "Draw deformation.png, stress_yy.png and "
                      "contact_pressure.png (3D: von_mises.png, the deformed "
                      "surface from two views) with matplotlib (needs Write "
                      "files).");
    prm.add_parameter(
      "Labels",
      label_entries,
      "Points labelled in deformation.png: 'name: x, y; ...' [m], e.g. the "
      "seed's points 1-10 (3D: 'name: x, y, z').",
      input::named_list_pattern(Patterns::List(Patterns::Double(), 2, 3)));
    prm.add_parameter("Picture time limit",
                      picture_time_limit,
                      "Seconds the picture script may take before it is "
                      "stopped (the result set is then kept without "
                      "pictures, with a warning).",
                      Patterns::Double(1));
    prm.add_parameter("Cells per VTU piece",
                      cells_per_piece,
                      "solution.vtu holds its cells in pieces of at most "
                      "this many (one file; ParaView reads the pieces as "
                      "one mesh): the writer's memory is that of one piece, "
                      "about 1 kB per cell, not of the whole mesh.",
                      Patterns::Integer(1));
    prm.add_parameter("Write files",
                      write_files,
                      "Write solution.vtu, contact CSVs and summary.json.");
    prm.leave_subsection();
  }



  template <int dim>
  void
  OutputWriter<dim>::check_parameters(const std::string &scene_file)
  {
    if (output_folder.empty())
      output_folder =
        "output/" + std::filesystem::path(scene_file).stem().string();
    // Every rank holds the results; rank 0 writes them, the others build
    // pieces of the VTU for it.
    if (parallel::rank() != 0)
      {
        builds_pieces = write_files;
        write_files   = false;
      }
    for (const auto &[name, point] : label_entries)
      {
        AssertThrow(!name.empty() && point.size() == dim,
                    ExcMessage("Output/Labels: '" + name +
                               "' needs a name and a point " +
                               (dim == 2 ? "'x, y' (the mesh is 2D)"
                                         : "'x, y, z' (the mesh is 3D)")));
        Point<dim> p;
        for (unsigned int d = 0; d < dim; ++d)
          p[d] = point[d];
        labels.emplace_back(name, p);
      }
  }



  template <int dim>
  void
  OutputWriter<dim>::prepare()
  {
    if (write_files)
      result_folder = std::make_unique<ResultFolder>(output_folder);
    // Started now, Python's and matplotlib's start (about 0.6 s) overlaps
    // the mesh and the solve instead of adding to the wait for the pictures.
    if (write_files && pictures)
      {
        const std::string script = find_script("pictures.py");
        picture_process          = std::make_unique<HelperProcess>();
        if (script.empty() ||
            !picture_process->start({"/usr/bin/python3", script}))
          picture_process.reset();
      }
  }



  template <int dim>
  void
  OutputWriter<dim>::commit()
  {
    picture_process.reset();
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
    const std::string folder = result_folder->staging() + "/" + subfolder;
    ProgramResult     result;
    if (picture_process && picture_process->running())
      result = picture_process->request(
        {std::filesystem::path(script_name).stem().string(), folder},
        picture_time_limit);
    else
      {
        const std::string log = staging("pictures.log");
        result = run_program({"/usr/bin/python3", script, folder},
                             log,
                             picture_time_limit);
        std::filesystem::remove(log);
      }
    if (result.exit_code == 0)
      return true;
    // "no pictures" means none: a drawing cut off at the time limit or by
    // an error leaves the figures it finished, which would stand beside
    // results they may not match.
    std::error_code ignored;
    for (const auto &entry :
         std::filesystem::directory_iterator(folder, ignored))
      if (entry.path().extension() == ".png")
        std::filesystem::remove(entry.path(), ignored);
    message = describe_failure(result,
                               "python3 " + script_name,
                               output_folder,
                               "Output/Picture time limit",
                               picture_time_limit);
    return false;
  }



  template <int dim>
  void
  OutputWriter<dim>::write_summary(
    const Results<dim>                         &results,
    const ContactSolution                      &contact,
    const Materials<dim>                       &materials,
    const std::map<std::string, double>        &wall_times,
    const std::string                          &solver,
    const std::map<std::string, double>        &solver_figures,
    const std::map<std::string, ErrorEstimate> &estimates) const
  {
    using json = nlohmann::ordered_json;
    json summary;
    summary["n_dofs"]   = results.n_dofs;
    summary["n_cells"]  = results.n_cells;
    summary["n_bodies"] = results.n_bodies;
    summary["elements"] = results.elements;
    const auto vector   = [](const auto &v) {
      std::vector<double> components(dim);
      for (unsigned int d = 0; d < dim; ++d)
        components[d] = v[d];
      return components;
    };
    summary["dimension"]            = dim;
    summary["applied_load"]         = vector(results.applied_load);
    summary["equilibrium_residual"] = results.equilibrium_residual;
    summary["energy"]               = results.energy;
    // The error bar of a quantity (null where the run has none).
    const auto error = [&estimates](const std::string &name) -> json {
      const auto found = estimates.find(name);
      if (found == estimates.end() || !std::isfinite(found->second.error))
        return nullptr;
      return found->second.error;
    };
    summary["energy_error"]     = error("energy");
    summary["max_displacement"] = results.max_displacement;
    for (const auto &[id, reaction] : results.reactions)
      summary["reactions"][std::to_string(id)] = vector(reaction);
    for (const auto &[id, range] : results.stress_yy_range)
      summary["stress_yy"][materials[id].name] = {
        {"material_id", id},
        {"min", range.first},
        {"max", range.second},
        {"min_error", error(materials[id].name + ": tau_yy min")},
        {"max_error", error(materials[id].name + ": tau_yy max")}};
    for (const auto &[id, value] : results.von_mises_max)
      summary["von_mises_max"][materials[id].name] = {
        {"material_id", id},
        {"max", value},
        {"max_error", error(materials[id].name + ": von Mises max")}};
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
          {"contact_length", i.contact_length},
          {"force_error", error("interface " + i.name + ": force")},
          {"max_pressure_error",
           error("interface " + i.name + ": peak pressure")},
          {"contact_length_error",
           error("interface " + i.name + ": contact length")},
          {"peak_location", vector(i.peak_location)},
          {"centre_of_pressure", vector(i.centre_of_pressure)},
          {"mean_pressure", i.mean_pressure}};
        // In 3D the slave boundary's share in contact is an area.
        if (dim == 3)
          summary["contact_interfaces"][i.name]["contact_area"] =
            i.contact_length;
        if (!contact.lambda_t.empty())
          {
            auto &entry = summary["contact_interfaces"][i.name];
            entry["tangential_force_on_slave"] =
              vector(i.tangential_force_on_slave);
            entry["n_stick"]              = i.n_stick;
            entry["n_slip"]               = i.n_slip;
            entry["stick_length"]         = i.stick_length;
            entry["slip_length"]          = i.slip_length;
            entry["max_slip"]             = i.max_slip;
            entry["max_accumulated_slip"] = i.max_accumulated_slip;
            // As contact_area: the same shares named for what they are in
            // 3D.
            if (dim == 3)
              {
                entry["stick_area"] = i.stick_length;
                entry["slip_area"]  = i.slip_length;
              }
          }
      }
    // How each bar was made (estimate_errors()).
    for (const auto &[name, estimate] : estimates)
      summary["error_estimates"][name] = {
        {"value", estimate.value},
        {"error", error(name)},
        {"extrapolated",
         std::isfinite(estimate.extrapolated) ? json(estimate.extrapolated)
                                              : json(nullptr)},
        {"observed_order",
         std::isfinite(estimate.order) ? json(estimate.order) : json(nullptr)},
        {"asymptotic", estimate.asymptotic},
        {"basis", estimate.basis}};
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
