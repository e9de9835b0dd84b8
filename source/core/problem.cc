#include <knee_contact/base/input.h>
#include <knee_contact/base/memory.h>
#include <knee_contact/base/parallel.h>
#include <knee_contact/base/scene_file.h>
#include <knee_contact/core/problem.h>
#include <knee_contact/core/scene_checks.h>
#include <knee_contact/physics/elasticity.h>
#include <knee_contact/physics/elements.h>
#include <knee_contact/physics/rigid_modes.h>

#include <deal.II/base/data_out_base.h>
#include <deal.II/base/mpi.h>
#include <deal.II/base/timer.h>
#include <deal.II/base/utilities.h>

#include <deal.II/lac/dynamic_sparsity_pattern.h>
#include <deal.II/lac/sparse_direct.h>

#include <deal.II/dofs/dof_tools.h>
#include <deal.II/grid/grid_generator.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <future>
#include <iomanip>
#include <iostream>
#include <limits>
#include <map>
#include <new>
#include <set>
#include <tuple>

namespace knee_contact
{
  namespace
  {
    // Parse @p scene_file into @p prm and turn ParameterHandler's
    // multi-line messages into one line.
    void
    parse_scene(ParameterHandler  &prm,
                const std::string &scene_file,
                const bool         skip_undefined)
    {
      AssertThrow(std::ifstream(scene_file).good(),
                  ExcMessage("cannot open scene file '" + scene_file + "'"));
      const auto extension = std::filesystem::path(scene_file).extension();
      AssertThrow(extension == ".prm" || extension == ".json",
                  ExcMessage("scene file '" + scene_file +
                             "' must end in .prm or .json"));
      // The file's size and nesting first: ParameterHandler's cost grows
      // with the square of the nesting (see SceneOutline).
      const SceneOutline outline(scene_file);
      try
        {
          prm.parse_input(scene_file, "", skip_undefined);
        }
      catch (const ExceptionBase &exc)
        {
          std::ostringstream info;
          exc.print_info(info);
          AssertThrow(false,
                      ExcMessage(scene_file + ": " +
                                 input::one_line(info.str())));
        }
      catch (const std::exception &exc)
        {
          AssertThrow(false,
                      ExcMessage(scene_file + ": " +
                                 input::one_line(exc.what())));
        }
    }


    // The format of every entry by its path ("Mesh/Source"), from deal.II's
    // Description listing: "set NAME = FORMAT" lines under "subsection"
    // lines, nested by indentation of two spaces. (Patterns::pattern_factory
    // would rebuild the patterns from the JSON listing, but deal.II 9.4's
    // crashes on a list of tuples.)
    std::map<std::string, std::string>
    formats(const ParameterHandler &prm)
    {
      std::ostringstream listing;
      prm.print_parameters(listing, ParameterHandler::Description);
      std::map<std::string, std::string> result;
      std::vector<std::string>           path;
      std::istringstream                 in(listing.str());
      std::string                        line;
      while (std::getline(in, line))
        {
          const std::size_t depth = line.find_first_not_of(' ') / 2;
          const std::string text  = Utilities::trim(line);
          if (text.rfind("subsection ", 0) == 0)
            {
              path.resize(std::min(depth, path.size()));
              path.push_back(text.substr(11));
            }
          else if (text.rfind("set ", 0) == 0 &&
                   text.find('=') != std::string::npos)
            {
              path.resize(std::min(depth, path.size()));
              std::string key;
              for (const auto &section : path)
                key += section + "/";
              const std::size_t equal = text.find('=');
              result[key + Utilities::trim(text.substr(4, equal - 4))] =
                Utilities::trim(text.substr(equal + 1));
            }
        }
      return result;
    }



    // One level of print_parameters()'s listing: entries first, then
    // subsections, as deal.II's PRM listing orders them.
    void
    print_listing(const nlohmann::json                     &node,
                  const std::string                        &path,
                  const std::map<std::string, std::string> &formats,
                  std::ostream                             &out)
    {
      const std::string indent((std::count(path.begin(), path.end(), '/')) * 2,
                               ' ');
      const auto        comment = [&](const std::string &text) {
        for (const auto &line :
             Utilities::break_text_into_lines(text, 76 - indent.size()))
          out << indent << "# " << line << '\n';
      };
      for (const auto &[name, entry] : node.items())
        if (entry.contains("value"))
          {
            comment(entry.at("documentation").get<std::string>());
            const auto format = formats.find(path + name);
            if (format != formats.end())
              comment("Format: " + format->second);
            out << indent << "set " << name << " = "
                << entry.at("default_value").get<std::string>() << "\n\n";
          }
      for (const auto &[name, section] : node.items())
        if (!section.contains("value"))
          {
            out << indent << "subsection " << name << '\n';
            print_listing(section, path + name + "/", formats, out);
            out << indent << "end\n\n";
          }
    }
  } // namespace



  template <int dim>
  typename ContactProblem<dim>::Counts
  ContactProblem<dim>::read_counts(const std::string &scene_file)
  {
    ContactProblem<dim> blank;
    ParameterHandler    prm;
    blank.add_parameters(prm, Counts{0, 0, 0, 0});
    parse_scene(prm, scene_file, true);
    return Counts{blank.materials.n_materials,
                  blank.boundary_conditions.n_conditions,
                  blank.contact_interfaces.n_interfaces,
                  blank.motions.n_motions};
  }



  template <int dim>
  void
  ContactProblem<dim>::print_parameters(std::ostream &out)
  {
    ContactProblem<dim> blank;
    ParameterHandler    prm;
    blank.add_parameters(prm, Counts());
    // deal.II's PRM listing has the defaults and documentation but not the
    // formats, its Description listing the formats but not the defaults:
    // the JSON listing (defaults, documentation) is walked and each entry
    // given its format from the Description listing (formats()).
    std::ostringstream json;
    prm.print_parameters(json, ParameterHandler::JSON);
    out << "# Every parameter of a scene: its documentation, its format and "
           "its default\n# (2D; in 3D vectors and points have a z "
           "component).\n";
    print_listing(nlohmann::json::parse(json.str()), "", formats(prm), out);
  }



  template <int dim>
  void
  ContactProblem<dim>::add_parameters(ParameterHandler &prm,
                                      const Counts     &counts)
  {
    mesh_input.add_parameters(prm);
    materials.add_parameters(prm, counts.n_materials);
    boundary_conditions.add_parameters(prm, counts.n_conditions);
    contact_interfaces.add_parameters(prm, counts.n_interfaces);
    active_set_solver.add_parameters(prm);
    load_cases.add_parameters(prm);
    motions.add_parameters(prm, counts.n_motions);
    output_writer.add_parameters(prm);
    verification.add_parameters(prm);
    refinement.add_parameters(prm);
  }



  template <int dim>
  ContactProblem<dim>::ContactProblem(const std::string &scene_file)
    : scene_file(scene_file)
  {
    const Counts       counts = read_counts(scene_file);
    const SceneOutline outline(scene_file);
    outline.check_numbered("Materials",
                           "Material",
                           counts.n_materials,
                           "Number of materials");
    outline.check_numbered("Boundary conditions",
                           "Condition",
                           counts.n_conditions,
                           "Number of conditions");
    outline.check_numbered("Contact",
                           "Interface",
                           counts.n_interfaces,
                           "Number of interfaces");
    outline.check_numbered("Load cases",
                           "Motion",
                           counts.n_motions,
                           "Number of motions");
    // Each entry is bound to the member it sets (add_parameter): parsing
    // fills them and refuses a value that does not match its pattern, with
    // the file and line; the checks that patterns cannot make follow.
    ParameterHandler prm;
    add_parameters(prm, counts);
    parse_scene(prm, scene_file, false);

    mesh_input.check_parameters(scene_file);
    materials.check_parameters(materials.constants_from_mesh
                                 ? mesh_input.deck_materials()
                                 : decltype(mesh_input.deck_materials())());
    boundary_conditions.check_parameters();
    contact_interfaces.check_parameters();
    active_set_solver.check_parameters(materials.max_youngs_modulus(),
                                       materials.min_youngs_modulus());
    load_cases.check_parameters();
    motions.check_parameters(load_cases.values());
    output_writer.check_parameters(scene_file);
    verification.check_parameters();
    refinement.check_parameters();
    mesh_input.adaptive = refinement.strategy != Refinement::Strategy::global;
    std::set<types::boundary_id> boundary_ids;
    for (const auto &condition : boundary_conditions.conditions())
      boundary_ids.insert(condition.ids.begin(), condition.ids.end());
    for (const auto &interface : contact_interfaces.interfaces())
      boundary_ids.insert({interface.slave_id, interface.master_id});
    mesh_input.set_scene_ids(materials.ids(), boundary_ids);
    scene_checks::check_roles(boundary_conditions, contact_interfaces);
  }



  template <int dim>
  std::ostream &
  ContactProblem<dim>::log() const
  {
    if (output_writer.test_mode())
      {
        quiet.str("");
        return quiet;
      }
    return std::cout;
  }



  template <int dim>
  void
  ContactProblem<dim>::release_distributed_mesh()
  {
    if (distributed)
      {
        // The DoF handler lets go of the distributed mesh before it goes.
        dof_handler.reinit(triangulation);
        distributed.reset();
      }
  }



  template <int dim>
  std::map<std::string, double>
  ContactProblem<dim>::phase_times(const TimerOutput &timer) const
  {
    auto times = timer.get_summary_data(TimerOutput::total_wall_time);
    for (const auto &[step, seconds] : mesh_times)
      times["mesh: " + step] = seconds;
    return times;
  }



  template <int dim>
  void
  ContactProblem<dim>::make_mesh(const int level, const bool distributed)
  {
    release_distributed_mesh();
    mesh_input.create(triangulation, level, distributed);
    fe =
      elements::displacement_element<dim>(elements::cell_kind(triangulation));
    materials.check_mesh(triangulation);
    boundary_conditions.check_mesh(triangulation);
    body_of_cell = compute_body_ids(triangulation, n_bodies);
    scene_checks::check_joints(triangulation, body_of_cell);
    contact_interfaces.check_mesh(triangulation, body_of_cell);
    // Moved bodies at the pose of the case being solved (the scene's mesh
    // is the pose's reference).
    motions.check_mesh(triangulation);
    motions.move(triangulation,
                 std::numeric_limits<double>::quiet_NaN(),
                 load_parameter);
  }



  template <int dim>
  void
  ContactProblem<dim>::check_scene()
  {
    make_mesh(0);
    std::cout << scene_file << ": " << triangulation.n_active_cells()
              << " cells, " << n_bodies << " bodies, "
              << contact_interfaces.interfaces().size()
              << " contact interfaces: OK" << std::endl;
  }



  template <int dim>
  std::string
  ContactProblem<dim>::distribution_reason(
    const Refinement::Strategy strategy) const
  {
    if (!may_distribute(strategy))
      return "";
    if (active_set_solver.linear_solver() == SolverPath::iterative)
      return "as Contact/Solver says";
    // The vector element's dofs: dim per vertex.
    const double n_dofs = double(dim) * triangulation.n_used_vertices();
    if (n_dofs >= min_distributed_dofs)
      return "automatic: a 3D mesh of " + std::to_string(int(n_dofs)) +
             " dofs on " + std::to_string(parallel::n_ranks()) +
             " ranks, at least " + std::to_string(int(min_distributed_dofs)) +
             "; the direct paths are not analysed";
    return "";
  }



  template <int dim>
  bool
  ContactProblem<dim>::may_distribute(const Refinement::Strategy strategy) const
  {
    // A uniform sequence makes each cycle's mesh whole anew
    // (MeshInput::create() at the cycle's level) and distributes it.
    if (parallel::n_ranks() == 1 || strategy != Refinement::Strategy::global ||
        !motions.empty())
      return false;
    const SolverPath path = active_set_solver.linear_solver();
    // 3D friction's Newton springs can take CG thousands of iterations
    // (doc/friction.md): the automatic choice keeps it on a direct path.
    bool friction = false;
    for (const auto &interface : contact_interfaces.interfaces())
      friction = friction || interface.friction != Friction::none;
    return path == SolverPath::iterative ||
           (path == SolverPath::automatic && dim == 3 && !friction);
  }



  template <int dim>
  void
  ContactProblem<dim>::make_distributable_mesh(
    const int                  level,
    const Refinement::Strategy strategy)
  {
    // Every rank holding the whole mesh took N times its memory on a
    // machine (1.6 GB a rank at 1e6 dofs) and N reads of its file at once.
    const auto make_checked_mesh = [&](const bool distributed) {
      make_mesh(level, distributed);
      scene_checks::check_finite_data(triangulation,
                                      materials,
                                      boundary_conditions);
    };
    release_distributed_mesh();
    Timer clock;
    distributed_reason = parallel::on_first_rank(
      [&]() {
        make_checked_mesh(true);
        if constexpr (dim == 3)
          {
            // The memory check's estimate, for summary.json (as
            // make_mesh() counts the mesh).
            const bool tetrahedra =
              triangulation.all_reference_cells_are_simplex();
            double first = 0, other = 0;
            estimated_distributed_bytes(tetrahedra
                                          ? 2. * triangulation.n_used_vertices()
                                          : double(
                                              triangulation.n_active_cells()),
                                        tetrahedra,
                                        first,
                                        other);
            estimated_first_MB = first / 1048576.;
            estimated_other_MB = other / 1048576.;
          }
        return distribution_reason(strategy);
      },
      "make and check the mesh");
    mesh_times["read"] += clock.wall_time();
    if (!distributed_reason.empty())
      {
        distribute();
        release_scene_mesh();
        for (const auto &[step, seconds] : distributed->times)
          mesh_times[step] += seconds;
        mesh_peak_MB = memory::peak_resident_MB();
        return;
      }
    // Kept whole (the automatic choice, below min_distributed_dofs): made
    // as on every rank, rank 0's anew too, since gmsh's outcome is shared
    // by all ranks (MeshInput).
    make_checked_mesh(false);
  }



  template <int dim>
  void
  ContactProblem<dim>::distribute()
  {
    // Rank 0 made and checked the whole mesh (make_distributable_mesh());
    // it is divided and sent, then freed.
    bool simplex = false;
    if (parallel::rank() == 0)
      {
        if (triangulation.n_levels() > 1)
          {
            // A refined mesh's description keeps its coarse cells and
            // their refinement, whose vertices have no index of the whole
            // mesh (the contact sides' keys): its cells become the cells
            // of one level.
            Triangulation<dim> flat;
            GridGenerator::flatten_triangulation(triangulation, flat);
            triangulation.clear();
            triangulation.copy_triangulation(flat);
            body_of_cell = compute_body_ids(triangulation, n_bodies);
          }
        name_bodies();
        simplex = elements::cell_kind(triangulation).is_simplex();
      }
    // What the other ranks did not make (a rank without cells could not
    // tell the cells' kind from its mesh).
    std::tie(n_bodies, body_names, simplex) =
      Utilities::MPI::broadcast(parallel::communicator(),
                                std::make_tuple(n_bodies, body_names, simplex));
    if (parallel::rank() != 0)
      fe = elements::displacement_element<dim>(
        simplex ? ReferenceCells::get_simplex<dim>()
                : ReferenceCells::get_hypercube<dim>());
    distributed = std::make_unique<DistributedMesh<dim>>();
    // The partition balances the entries of the condensed system's rows,
    // which contact widens near its surfaces (partition_weights()).
    Timer               clock;
    std::vector<double> weights =
      parallel::rank() == 0 && parallel::n_ranks() > 1
        ? partition_weights(triangulation, contact_interfaces)
        : std::vector<double>();
    const double weights_time = clock.wall_time();
    distribute_mesh(
      triangulation, body_of_cell, n_bodies, std::move(weights), *distributed);
    distributed->times["partition"] += weights_time;
    dof_handler.reinit(distributed->triangulation);
    triangulation.clear();
    body_of_cell = distributed->body_of_cell;
  }



  template <int dim>
  void
  ContactProblem<dim>::name_bodies()
  {
    body_names.assign(n_bodies, "");
    std::vector<std::set<types::material_id>> body_materials(n_bodies);
    for (const auto &cell : triangulation.active_cell_iterators())
      body_materials[body_of_cell[cell->active_cell_index()]].insert(
        cell->material_id());
    for (unsigned int b = 0; b < n_bodies; ++b)
      for (const auto id : body_materials[b])
        body_names[b] +=
          (body_names[b].empty() ? "" : ", ") + materials[id].name;
  }



  template <int dim>
  void
  ContactProblem<dim>::setup_system()
  {
    if (distributed)
      {
        // The bodies and their names are the whole mesh's (distribute()).
        dof_handler.reinit(distributed->triangulation);
        body_of_cell = distributed->body_of_cell;
      }
    else
      {
        dof_handler.reinit(triangulation);
        body_of_cell = compute_body_ids(triangulation, n_bodies);
        name_bodies();
      }
    dof_handler.distribute_dofs(*fe);
    elements::renumber_vertex_wise(dof_handler);

    boundary_conditions.make_constraints(dof_handler, constraints);
    contact_pairs =
      contact_interfaces.make_pairs(dof_handler,
                                    constraints,
                                    distributed ? &distributed->vertex_id
                                                : nullptr);
    friction_rows.clear();
    if (contact_pairs.frictional())
      friction_rows = contact_pairs.solver_rows();

    // In 3D the friction loop's Newton step sets springs on the two
    // tangential rows of a slipping pair (solve_with_friction()).
    std::vector<std::vector<unsigned int>> spring_rows;
    if (dim == 3 && contact_pairs.frictional())
      {
        const FrictionRowLayout at{
          static_cast<unsigned int>(contact_pairs.size()), dim};
        for (unsigned int p = 0; p < at.n_pairs; ++p)
          spring_rows.push_back({at.tangential(0, p), at.tangential(1, p)});
      }
    if (distributed)
      {
        // Each rank's rows, from its cells.
        TrilinosWrappers::SparsityPattern mesh_pattern;
        make_distributed_pattern(dof_handler, mesh_pattern);
        distributed_pattern =
          std::make_unique<TrilinosWrappers::SparsityPattern>();
        ActiveSetSolver::make_sparsity_pattern(mesh_pattern,
                                               constraints,
                                               rows_for_solver(),
                                               *distributed_pattern,
                                               contact_pairs.frictional(),
                                               spring_rows);
        sparsity_pattern.reinit(0, 0, 0);
      }
    else
      {
        DynamicSparsityPattern mesh_pattern(dof_handler.n_dofs());
        DoFTools::make_sparsity_pattern(dof_handler, mesh_pattern);
        ActiveSetSolver::make_sparsity_pattern(mesh_pattern,
                                               constraints,
                                               rows_for_solver(),
                                               sparsity_pattern,
                                               contact_pairs.frictional(),
                                               spring_rows);
        distributed_pattern.reset();
      }
    // C is made by assemble_system(), whole or as the solver path's rows.
    system_matrix.clear();
    rigid_modes =
      std::make_unique<RigidModes<dim>>(dof_handler, body_of_cell, body_names);
  }



  template <int dim>
  int
  ContactProblem<dim>::run()
  {
    TimerOutput timer(log(), TimerOutput::never, TimerOutput::wall_times);
    if (refinement.target_error > 0)
      {
        // The names cycle_quantities() gives a contact quantity.
        std::vector<std::string> names = {"energy"};
        if (!contact_interfaces.interfaces().empty())
          names.emplace_back("peak pressure");
        for (const auto &i : contact_interfaces.interfaces())
          for (const char *what : {"peak pressure", "force", "contact length"})
            names.push_back("interface " + i.name + ": " + what);
        if (std::find(names.begin(), names.end(), refinement.target_quantity) ==
            names.end())
          {
            std::string list;
            for (const auto &name : names)
              list += (list.empty() ? "'" : ", '") + name + "'";
            AssertThrow(false,
                        ExcMessage("Refinement/Target quantity '" +
                                   refinement.target_quantity +
                                   "' is not one of " + list));
          }
      }
    output_writer.prepare();
    set_load_parameter(load_cases.values()[0]);

    // A study runs the uniform sequence first; the files and checks are
    // those of the last sequence.
    std::vector<Refinement::Strategy> strategies = {refinement.strategy};
    if (refinement.strategy == Refinement::Strategy::compare)
      strategies = {Refinement::Strategy::global,
                    Refinement::Strategy::adaptive};
    std::vector<std::vector<CycleRecord>> sequences;
    Results<dim>                          results;
    for (const auto strategy : strategies)
      sequences.push_back(run_cycles(strategy, timer, results));
    for (const auto &records : sequences)
      if (records.size() > 1)
        print_convergence_table(records,
                                dim,
                                !output_writer.test_mode(),
                                !output_writer.test_mode(),
                                std::cout);

    print_results(results);

    std::vector<std::vector<Errors>> errors(sequences.size());
    std::vector<std::vector<double>> n_dofs(sequences.size());
    for (unsigned int s = 0; s < sequences.size(); ++s)
      for (const auto &record : sequences[s])
        {
          errors[s].push_back(record.errors);
          n_dofs[s].push_back(record.n_dofs);
        }
    unsigned int n_failed = verification.check(results,
                                               contact_solution,
                                               !contact_pairs.empty(),
                                               errors.back(),
                                               n_dofs.back(),
                                               std::cout);
    if (sequences.size() > 1)
      n_failed += verification.check_study(
        errors[0], n_dofs[0], errors[1], n_dofs[1], std::cout);

    if (load_cases.values().size() > 1)
      n_failed += run_load_cases(results, sequences, timer);
    else if (output_writer.takes_part())
      {
        // The output reads the results, not the solver: its matrices,
        // hierarchy or factor go before DataOut's patches are built, which
        // on the iterative path set the run's peak (doc/parallel.md), and
        // their pages go back to the system (four ranks at 1e6 dofs: the
        // output's 1 150-1 200 MB a rank -> 710-730).
        contact_system.reset();
        memory::return_free_heap();
        write_result_set(results, sequences, timer);
      }

    const auto wall_times = phase_times(timer);
    output_writer.commit();
    if (!output_writer.test_mode())
      {
        std::cout << "wall time [s]:";
        for (const auto &[phase, seconds] : wall_times)
          std::cout << "  " << phase << " " << std::setprecision(3) << seconds;
        std::cout << std::endl;
        if (output_writer.enabled())
          std::cout << "results in " << output_writer.folder() << "/"
                    << std::endl;
      }

    if (!contact_solution.converged)
      {
        std::cerr << "knee_contact: not converged: " << contact_solution.failure
                  << (output_writer.enabled()
                        ? " (last iterate written with converged = false)"
                        : "")
                  << std::endl;
        return ExitCode::not_converged;
      }
    if (n_failed > 0)
      {
        std::cerr << "knee_contact: " << n_failed
                  << " verification check(s) failed" << std::endl;
        return ExitCode::verification_failed;
      }
    return ExitCode::success;
  }



  unsigned int
  scene_dimension(const std::string &scene_file)
  {
    ParameterHandler prm;
    MeshInput<2>     mesh_input;
    mesh_input.add_parameters(prm);
    parse_scene(prm, scene_file, true);
    return scene_dimension(mesh_input, scene_file);
  }



  template class ContactProblem<2>;
  template class ContactProblem<3>;
} // namespace knee_contact
