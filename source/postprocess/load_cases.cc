#include <knee_contact/base/input.h>
#include <knee_contact/postprocess/load_cases.h>

#include <cmath>
#include <cstdio>
#include <iomanip>
#include <sstream>

namespace knee_contact
{
  namespace
  {
    // More cases than this is a typing error (a step of 1e-9), not a study.
    constexpr unsigned int max_cases = 100000;
  } // namespace



  void
  LoadCases::add_parameters(ParameterHandler &prm)
  {
    prm.enter_subsection("Load cases");
    prm.add_parameter(
      "Values of t",
      entries,
      "The load parameter t of each load case, separated by ','; an entry "
      "'first:step:last' stands for first, first+step, ..., last. Traction, "
      "pressure and body force expressions (and exact solutions) may use t; "
      "displacement conditions may not. Empty: one case at t = 0. With "
      "friction the cases are a load path: each starts where the previous "
      "ended and the slip accumulates (the first from the unloaded state).",
      Patterns::List(
        Patterns::Anything(), 0, Patterns::List::max_int_value, ","));
    prm.leave_subsection();
  }



  void
  LoadCases::check_parameters()
  {
    const std::string parameter = "Load cases/Values of t";
    t.clear();
    for (const auto &entry : entries)
      {
        const auto range = input::split(entry, ':');
        if (range.size() == 1)
          t.push_back(input::to_double(entry, parameter));
        else
          {
            AssertThrow(range.size() == 3,
                        ExcMessage("parameter '" + parameter + "': '" + entry +
                                   "' is neither a number nor "
                                   "first:step:last"));
            const double first = input::to_double(range[0], parameter);
            const double step  = input::to_double(range[1], parameter);
            const double last  = input::to_double(range[2], parameter);
            const double n     = (last - first) / step;
            if (step > 0 && last >= first && !(n < max_cases))
              {
                std::ostringstream count;
                count << std::setprecision(3) << n + 1;
                AssertThrow(false,
                            ExcMessage("parameter '" + parameter +
                                       "': range '" + entry + "' gives " +
                                       count.str() + " load cases; at most " +
                                       std::to_string(max_cases)));
              }
            AssertThrow(step > 0 && last >= first &&
                          std::abs(n - std::round(n)) <= 1e-9 * (1 + n),
                        ExcMessage("parameter '" + parameter + "': range '" +
                                   entry +
                                   "' needs step > 0, last >= first and last "
                                   "- first a multiple of step"));
            for (long i = 0; i <= std::lround(n); ++i)
              t.push_back(i == std::lround(n) ? last : first + i * step);
          }
        AssertThrow(t.size() <= max_cases,
                    ExcMessage("parameter '" + parameter + "': more than " +
                               std::to_string(max_cases) + " load cases"));
      }
    if (t.empty())
      t = {0.};
  }



  std::string
  LoadCases::folder(const unsigned int index)
  {
    char name[32];
    std::snprintf(name, sizeof(name), "case_%03u", index);
    return name;
  }



  template <int dim>
  void
  LoadCases::write_csv(const std::vector<Record<dim>> &records,
                       std::ostream                   &out)
  {
    if (records.empty())
      return;
    const Results<dim> &first = records.front().results;
    out << "case,t,iterations,converged,solve_time,energy,energy_error,"
           "peak_pressure_error,max_displacement";
    for (unsigned int d = 0; d < dim; ++d)
      out << ",load_"
          << "xyz"[d];
    for (const auto &[id, reaction] : first.reactions)
      for (unsigned int d = 0; d < dim; ++d)
        out << ",reaction_" << id << '_' << "xyz"[d];
    for (const auto &i : first.interfaces)
      {
        out << ',' << i.name << "_active_pairs," << i.name << "_force,"
            << i.name << "_peak_pressure," << i.name
            << (dim == 2 ? "_contact_length" : "_contact_area");
        if (i.friction)
          // In 3D the sticking and slipping shares are areas.
          out << ',' << i.name << (dim == 2 ? "_stick_length," : "_stick_area,")
              << i.name << (dim == 2 ? "_slip_length," : "_slip_area,")
              << i.name << "_max_slip," << i.name << "_max_accumulated_slip";
      }
    out << '\n' << std::setprecision(12);
    for (unsigned int c = 0; c < records.size(); ++c)
      {
        const Record<dim>  &r       = records[c];
        const Results<dim> &results = r.results;
        out << c << ',' << r.t << ',' << r.n_iterations << ','
            << (r.converged ? "true" : "false") << ',' << r.solve_time << ','
            << results.energy << ',' << r.energy_error << ','
            << r.peak_pressure_error << ',' << results.max_displacement;
        for (unsigned int d = 0; d < dim; ++d)
          out << ',' << results.applied_load[d];
        for (const auto &[id, reaction] : results.reactions)
          for (unsigned int d = 0; d < dim; ++d)
            out << ',' << reaction[d];
        for (const auto &i : results.interfaces)
          {
            out << ',' << i.n_active << ',' << i.force << ',' << i.max_pressure
                << ',' << i.contact_length;
            if (i.friction)
              out << ',' << i.stick_length << ',' << i.slip_length << ','
                  << i.max_slip << ',' << i.max_accumulated_slip;
          }
        out << '\n';
      }
  }



  template <int dim>
  void
  LoadCases::print_table(const std::vector<Record<dim>> &records,
                         const bool                      with_times,
                         std::ostream                   &out)
  {
    // 3D: energies in J and contact areas in m^2.
    out << "load cases:\n"
        << (dim == 2 ? "  case          t  iterations  energy [J/m]"
                       "  peak pressure [Pa]  contact length [m]"
                     : "  case          t  iterations    energy [J]"
                       "  peak pressure [Pa]  contact area [m^2]")
        << (with_times
              ? (dim == 2 ? "  energy bar [J/m]" : "    energy bar [J]")
              : "")
        << (with_times ? "  peak bar [Pa]  solve [s]" : "") << '\n';
    for (unsigned int c = 0; c < records.size(); ++c)
      {
        const Record<dim> &r    = records[c];
        double             peak = 0, length = 0;
        for (const auto &i : r.results.interfaces)
          {
            peak = std::max(peak, i.max_pressure);
            length += i.contact_length;
          }
        out << "  " << std::setw(4) << c << std::setw(11)
            << std::setprecision(4) << r.t << std::setw(12) << r.n_iterations
            << std::scientific << std::setprecision(5) << std::setw(14)
            << r.results.energy << std::setw(20) << peak << std::setw(20)
            << length << std::defaultfloat << std::setprecision(3);
        // The bar and the times only outside test mode (numdiff compares
        // test output).
        if (with_times)
          out << std::scientific << std::setprecision(2) << std::setw(18)
              << r.energy_error << std::setw(15) << r.peak_pressure_error
              << std::defaultfloat << std::setprecision(3) << std::setw(11)
              << r.solve_time;
        out << (r.converged ? "" : "  NOT converged") << '\n';
      }
    out << std::flush;
  }


  template void
  LoadCases::write_csv(const std::vector<Record<2>> &, std::ostream &);
  template void
  LoadCases::write_csv(const std::vector<Record<3>> &, std::ostream &);
  template void
  LoadCases::print_table(const std::vector<Record<2>> &,
                         const bool,
                         std::ostream &);
  template void
  LoadCases::print_table(const std::vector<Record<3>> &,
                         const bool,
                         std::ostream &);
} // namespace knee_contact
