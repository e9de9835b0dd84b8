#include <knee_contact/postprocess/study.h>

#include <deal.II/base/convergence_table.h>

#include <cmath>
#include <iomanip>
#include <limits>
#include <tuple>

namespace knee_contact
{
  namespace
  {
    // The errors a study reports, by column name.
    const std::vector<std::pair<std::string, double Errors::*>> error_columns =
      {{"L2 error", &Errors::l2_relative},
       {"energy error", &Errors::energy_relative},
       {"peak pressure error", &Errors::peak_pressure_relative},
       {"contact length error", &Errors::contact_length_error},
       {"pressure L2 error", &Errors::pressure_l2_relative},
       {"energy vs reference", &Errors::energy_reference_relative},
       {"extreme stress_yy error", &Errors::stress_extreme_relative}};

    // The effectivity indices of the error bars: the estimated relative
    // error over the true one, where the run knows the true one (a
    // Verification reference or an exact solution); NaN otherwise. The
    // energy's true error is |a(u_h,u_h) - a_ref| / a_ref, or with an exact
    // solution a(u - u_h, u - u_h) / a(u,u) = energy_relative^2.
    std::pair<double, double>
    effectivities(const CycleRecord &r)
    {
      const double true_energy =
        std::isfinite(r.errors.energy_reference_relative)
          ? r.errors.energy_reference_relative
          : r.errors.energy_relative * r.errors.energy_relative;
      const auto ratio = [](const double estimate, const double error) {
        return std::isfinite(estimate) && std::isfinite(error) && error > 0
                 ? estimate / error
                 : std::numeric_limits<double>::quiet_NaN();
      };
      return {ratio(r.estimated_peak_pressure_error,
                    r.errors.peak_pressure_relative),
              ratio(r.estimated_energy_error, true_energy)};
    }
  } // namespace



  void
  print_convergence_table(const std::vector<CycleRecord> &records,
                          const unsigned int              dimension,
                          const bool                      with_times,
                          const bool                      with_estimates,
                          std::ostream                   &out)
  {
    dealii::ConvergenceTable table;
    for (const CycleRecord &r : records)
      {
        table.add_value("cycle", r.cycle);
        table.add_value("dofs", r.n_dofs);
        if (r.n_pairs > 0)
          {
            table.add_value("pairs", r.n_pairs);
            table.add_value("iterations", r.n_iterations);
            table.add_value("peak pressure", r.peak_pressure);
            table.set_scientific("peak pressure", true);
          }
        for (const auto &[name, error] : error_columns)
          if (!std::isnan(records.front().errors.*error))
            {
              table.add_value(name, r.errors.*error);
              table.set_scientific(name, true);
              table.set_precision(name, 3);
            }
        if (with_estimates)
          for (const auto &[name, value] :
               {std::pair<std::string, double>{"est. peak pressure error",
                                               r.estimated_peak_pressure_error},
                {"est. energy error", r.estimated_energy_error}})
            if (r.n_pairs > 0 || name == "est. energy error")
              {
                table.add_value(name, value);
                table.set_scientific(name, true);
                table.set_precision(name, 2);
              }
        // Beside the bars, their effectivity where the true error is
        // known (bar / true error: above 1 the bar holds the error).
        if (with_estimates)
          {
            const auto [peak, energy] = effectivities(r);
            const auto &first         = effectivities(records.front());
            for (const auto &[name, value, shown] :
                 {std::tuple<std::string, double, bool>{
                    "peak effectivity",
                    peak,
                    r.n_pairs > 0 &&
                      std::isfinite(
                        records.back().errors.peak_pressure_relative)},
                  {"energy effectivity", energy, std::isfinite(first.second)}})
              if (shown)
                {
                  table.add_value(name, value);
                  table.set_precision(name, 2);
                }
          }
        if (with_times)
          {
            table.add_value("time [s]", r.total_time);
            table.add_value("memory [MB]", r.peak_memory);
          }
      }
    // Rates of errors at round-off (an exact patch test) are noise, and not
    // shown: below 1e-8 relative on every mesh (the energy error is the
    // square root of a difference of energies, so its round-off is about
    // sqrt(1e-16)).
    const auto above_round_off = [&records](double Errors::*error) {
      for (const CycleRecord &r : records)
        if (r.errors.*error > 1e-8)
          return true;
      return false;
    };
    if (records.size() > 1)
      for (const auto &[name, error] : error_columns)
        if (!std::isnan(records.front().errors.*error) &&
            above_round_off(error))
          table.evaluate_convergence_rates(
            name,
            "dofs",
            dealii::ConvergenceTable::reduction_rate_log2,
            dimension);
    out << records.front().strategy << " refinement:" << std::endl;
    table.write_text(out);
  }



  void
  write_study_csv(const std::vector<CycleRecord> &records, std::ostream &out)
  {
    out << "strategy,cycle,cells,dofs,pairs,iterations,peak_pressure,energy";
    for (const auto &column : error_columns)
      {
        std::string name = column.first;
        for (char &c : name)
          if (c == ' ')
            c = '_';
        out << ',' << name;
      }
    const auto &phases = records.front().wall_time;
    for (const auto &phase : phases)
      out << ",time_" << phase.first;
    const char *solver_columns[] = {"contact_solve",
                                    "reference_solve",
                                    "contact_unknowns",
                                    "factor_memory_MB",
                                    "dense_memory_MB"};
    out << ",time_total,peak_memory_MB,solver";
    // The error bars of the peak pressure and the energy relative to the
    // values, from the cycles up to this one (beside the true errors
    // above: the estimates' effectivity), after the solver's columns.
    const std::string estimate_columns =
      ",estimated_peak_pressure_error,estimated_energy_error,"
      "recovered_energy_error,peak_pressure_effectivity,energy_effectivity";
    for (const char *column : solver_columns)
      out << ',' << column;
    out << estimate_columns << '\n' << std::setprecision(10);
    for (const CycleRecord &r : records)
      {
        const auto [peak_effectivity, energy_effectivity] = effectivities(r);
        out << r.strategy << ',' << r.cycle << ',' << r.n_cells << ','
            << r.n_dofs << ',' << r.n_pairs << ',' << r.n_iterations << ','
            << r.peak_pressure << ',' << r.energy;
        for (const auto &column : error_columns)
          out << ',' << r.errors.*(column.second);
        for (const auto &phase : phases)
          {
            const auto it = r.wall_time.find(phase.first);
            out << ',' << (it == r.wall_time.end() ? 0. : it->second);
          }
        out << ',' << r.total_time << ',' << r.peak_memory << ',' << r.solver;
        for (const char *column : solver_columns)
          {
            const auto it = r.solver_figures.find(column);
            out << ',' << (it == r.solver_figures.end() ? 0. : it->second);
          }
        out << ',' << r.estimated_peak_pressure_error << ','
            << r.estimated_energy_error << ','
            << r.recovered_energy_error / std::abs(r.energy) << ','
            << peak_effectivity << ',' << energy_effectivity << '\n';
      }
  }
} // namespace knee_contact
