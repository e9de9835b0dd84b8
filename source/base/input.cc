#include <knee_contact/base/input.h>

#include <deal.II/lac/vector.h>

#include <nlohmann/json.hpp>

#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace knee_contact
{
  namespace input
  {
    std::string
    resolve_path(const std::string &path, const std::string &scene_file)
    {
      const std::filesystem::path p(path);
      if (p.is_absolute() || path.empty())
        return path;
      // The scene's own folder, through symbolic links (build/knee.prm links
      // to prm/knee.prm, whose mesh lies beside it).
      return (std::filesystem::weakly_canonical(scene_file).parent_path() / p)
        .lexically_normal()
        .string();
    }



    std::vector<std::string>
    split(const std::string &text, const char separator)
    {
      std::vector<std::string> parts;
      std::string              part;
      std::istringstream       in(text);
      while (std::getline(in, part, separator))
        parts.push_back(Utilities::trim(part));
      if (!text.empty() && text.back() == separator)
        parts.emplace_back();
      return parts;
    }



    Patterns::List
    expression_pattern(const unsigned int max_components, const bool optional)
    {
      return Patterns::List(Patterns::Anything(),
                            optional ? 0 : 1,
                            max_components,
                            ";");
    }



    Patterns::List
    named_list_pattern(const Patterns::PatternBase &value_pattern)
    {
      return Patterns::List(Patterns::Tuple(":",
                                            Patterns::Anything(),
                                            value_pattern),
                            0,
                            Patterns::List::max_int_value,
                            ";");
    }



    std::optional<double>
    number(const std::string &text)
    {
      // std::stod skips leading white space and stops at the first
      // character that is not part of a number: the rest must be used too.
      std::size_t end   = 0;
      double      value = 0;
      try
        {
          value = std::stod(text, &end);
        }
      catch (...)
        {
          return std::nullopt;
        }
      if (end == 0 || end != text.size() || !std::isfinite(value))
        return std::nullopt;
      return value;
    }



    bool
    numbers_only(const std::string &expression)
    {
      for (const auto &part : split(expression, ';'))
        if (!number(part))
          return false;
      return true;
    }



    double
    to_double(const std::string &text, const std::string &parameter)
    {
      const auto value = number(Utilities::trim(text));
      AssertThrow(value.has_value(),
                  ExcMessage("parameter '" + parameter + "': '" + text +
                             "' is not a finite number"));
      return *value;
    }



    template <int dim>
    std::unique_ptr<FunctionParser<dim>>
    parse_expression(const std::string &expression,
                     const unsigned int n_components,
                     const std::string &parameter,
                     const std::string &constants,
                     const bool         load)
    {
      const auto parts = split(expression, ';');
      // A vector of the other dimension is a scene written for a mesh of
      // the other dimension: say which one this is.
      const bool other_dimension =
        n_components == dim && parts.size() == (dim == 2 ? 3u : 2u);
      AssertThrow(parts.size() == n_components,
                  ExcMessage("parameter '" + parameter + "': expected " +
                             std::to_string(n_components) +
                             " component(s) separated by ';', got '" +
                             expression + "'" +
                             (!other_dimension ? ""
                              : dim == 2 ? " (the mesh is 2D: give x and y "
                                           "components)"
                                         : " (the mesh is 3D: give x, y and "
                                           "z components)")));
      std::map<std::string, double> constant_map = {{"pi", numbers::PI}};
      for (const auto &c : split(constants, ','))
        if (!c.empty())
          {
            const auto name_value = split(c, '=');
            AssertThrow(name_value.size() == 2 && !name_value[0].empty(),
                        ExcMessage("parameter '" + parameter + "': constant '" +
                                   c + "' is not of the form name=value"));
            constant_map[name_value[0]] =
              to_double(name_value[1], parameter + " constants");
          }

      // The finite difference step only matters for gradients of reference
      // solutions; a fourth order formula with h = 1e-4 keeps their error
      // near 1e-13 for smooth fields.
      auto function =
        std::make_unique<FunctionParser<dim>>(n_components, 0., 1e-4);
      function->set_formula(AutoDerivativeFunction<dim>::FourthOrder);
      // deal.II prints muparser's complaint to std::cerr before it throws;
      // silence that, the message below says it in one line.
      std::ostringstream    muparser_output;
      std::streambuf *const cerr_buffer =
        std::cerr.rdbuf(muparser_output.rdbuf());
      Vector<double> values(n_components);
      // A generic point: no coordinate 0 or 1, where singular expressions
      // (1/x, log(y - 1)) would hide.
      Point<dim> generic;
      for (unsigned int d = 0; d < dim; ++d)
        generic[d] =
          std::array<double, 3>{{0.123456789, 0.234567891, 0.345678912}}[d];
      const std::string variables = dim == 2 ? "x,y" : "x,y,z";
      try
        {
          function->initialize(load ? variables + ",t" : variables,
                               parts,
                               constant_map,
                               load);
          function->vector_value(generic, values);
          std::cerr.rdbuf(cerr_buffer);
        }
      catch (const std::exception &exc)
        {
          std::cerr.rdbuf(cerr_buffer);
          const std::string what = one_line(exc.what());
          AssertThrow(false,
                      ExcMessage(
                        "parameter '" + parameter +
                        "': cannot evaluate expression '" + expression + "' (" +
                        what + ")" +
                        (!load && what.find("\"t\"") != std::string::npos
                           ? "; the load parameter t may only appear in "
                             "traction, pressure, body force and "
                             "exact-solution expressions"
                           : "")));
        }
      // A value that is not finite at a generic point is a mistake (1/0,
      // log(0)), not a singularity the scene means.
      for (unsigned int c = 0; c < n_components; ++c)
        AssertThrow(std::isfinite(values(c)),
                    ExcMessage("parameter '" + parameter + "': '" + expression +
                               "' is not finite (inf or nan) at " +
                               (dim == 2 ? "(x, y) = (0.123456789, "
                                           "0.234567891)"
                                         : "(x, y, z) = (0.123456789, "
                                           "0.234567891, 0.345678912)")));
      return function;
    }



    double
    evaluate_constant(const std::string &expression,
                      const std::string &parameter)
    {
      const auto   function = parse_expression<2>(expression, 1, parameter);
      const double value    = function->value(Point<2>());
      AssertThrow(std::isfinite(value),
                  ExcMessage("parameter '" + parameter + "': '" + expression +
                             "' is not finite"));
      return value;
    }



    std::string
    format(const double value)
    {
      std::ostringstream out;
      out << std::setprecision(6) << value;
      return out.str();
    }



    std::string
    one_line(const std::string &text)
    {
      // deal.II's ExceptionBase::what() holds "Additional information:"
      // followed by the message, then a stack trace; keep only the message.
      std::string message = text;
      const auto  info    = message.find("Additional information:");
      if (info != std::string::npos)
        message = message.substr(info + 23);
      const auto trace = message.find("Stacktrace:");
      if (trace != std::string::npos)
        message = message.substr(0, trace);
      std::string line;
      bool        space = false;
      for (const char c : message)
        if (c == '\n' || c == '\t' || c == ' ' || c == '\r')
          space = !line.empty();
        else
          {
            if (space)
              line += ' ';
            // Control characters (from a binary file) would garble the
            // terminal.
            line += (static_cast<unsigned char>(c) < 32 || c == 127) ? '?' : c;
            space = false;
          }
      // Strip a line of dashes deal.II adds around its messages.
      while (!line.empty() && line.back() == '-')
        line.pop_back();
      return cap(Utilities::trim(line));
    }



    std::string
    cap(const std::string &line)
    {
      // A value echoed in quotes ('...' or ParameterHandler's <...>) keeps
      // its first 200 bytes, cut at a character boundary.
      const auto cut = [](const std::string &text, std::size_t n) {
        while (n > 0 && n < text.size() &&
               (static_cast<unsigned char>(text[n]) & 0xC0) == 0x80)
          --n;
        return text.substr(0, n);
      };
      std::string result;
      for (std::size_t i = 0; i < line.size();)
        {
          const char open  = line[i];
          const char close = open == '\'' ? '\'' : (open == '<' ? '>' : '\0');
          const std::size_t end =
            close ? line.find(close, i + 1) : std::string::npos;
          if (end != std::string::npos && end - i - 1 > 200)
            {
              const std::string value = line.substr(i + 1, end - i - 1);
              result += open + cut(value, 200) + "... (" +
                        std::to_string(value.size()) + " characters)" + close;
              i = end + 1;
            }
          else
            result += line[i++];
        }
      return result.size() > 1000 ? cut(result, 1000) + "..." : result;
    }



    void
    check_name(const std::string &name, const std::string &parameter)
    {
      AssertThrow(!name.empty() && name.size() <= 100,
                  ExcMessage(parameter + ": a name needs 1 to 100 bytes"));
      for (std::size_t i = 0; i < name.size(); ++i)
        AssertThrow(static_cast<unsigned char>(name[i]) >= 32 && name[i] != 127,
                    ExcMessage(parameter + ": '" + one_line(name) +
                               "' holds a control character (byte " +
                               std::to_string(i + 1) + ")"));
      // summary.json must stay valid JSON: nlohmann-json's encoder checks
      // UTF-8 strictly (overlong forms and surrogates too).
      try
        {
          (void)nlohmann::json(name).dump();
        }
      catch (const nlohmann::json::exception &)
        {
          AssertThrow(false,
                      ExcMessage(parameter + ": '" + one_line(name) +
                                 "' is not valid UTF-8 text"));
        }
    }

    template std::unique_ptr<FunctionParser<2>>
    parse_expression<2>(const std::string &,
                        const unsigned int,
                        const std::string &,
                        const std::string &,
                        const bool);
    template std::unique_ptr<FunctionParser<3>>
    parse_expression<3>(const std::string &,
                        const unsigned int,
                        const std::string &,
                        const std::string &,
                        const bool);
  } // namespace input
} // namespace knee_contact
