#ifndef knee_contact_input_h
#define knee_contact_input_h

#include <deal.II/base/function_parser.h>
#include <deal.II/base/parameter_handler.h>
#include <deal.II/base/point.h>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace knee_contact
{
  using namespace dealii;

  /**
   * Helpers for reading a scene: paths relative to the scene file, run-time
   * expressions (u0, P, F, references) and list entries. Every error names
   * the parameter it came from, so the program can print it on one line.
   */
  namespace input
  {
    /**
     * Resolve @p path against the folder of @p scene_file unless it is
     * absolute: ctest and users run the program from anywhere.
     */
    std::string
    resolve_path(const std::string &path, const std::string &scene_file);

    /**
     * Parse @p expression with @p n_components components (separated by ';')
     * in the variables x, y (and z in 3D) and the constants "pi" and @p
     * constants
     * ("name=value, ..."). Throws an ExcMessage that names @p parameter if the
     * expression does not parse. A @p load expression (traction, pressure,
     * body force, exact solutions) may also use t, the load parameter of the
     * scene's load cases (FunctionParser's time, set by set_time()); elsewhere
     * t is an unknown name and the message says where it is allowed.
     */
    template <int dim>
    std::unique_ptr<FunctionParser<dim>>
    parse_expression(const std::string &expression,
                     const unsigned int n_components,
                     const std::string &parameter,
                     const std::string &constants = "",
                     const bool         load      = false);

    /**
     * Declare the Selection entry @p entry and bind it to @p value through
     * @p names (the word in the scene file, the value it stands for); the
     * default is the name of @p value's value. This is add_parameter() for
     * enums, which deal.II 9.4's Patterns::Tools::Convert does not convert
     * (it does from 9.5 on): declare_entry() and add_action(), the two
     * steps add_parameter() is made of.
     */
    template <typename Value>
    void
    add_selection(ParameterHandler                                 &prm,
                  const std::string                                &entry,
                  Value                                            &value,
                  const std::vector<std::pair<std::string, Value>> &names,
                  const std::string &documentation)
    {
      std::string selection, default_name;
      for (const auto &[name, v] : names)
        {
          selection += (selection.empty() ? "" : "|") + name;
          if (v == value && default_name.empty())
            default_name = name;
        }
      prm.declare_entry(entry,
                        default_name,
                        Patterns::Selection(selection),
                        documentation);
      prm.add_action(entry, [&value, names](const std::string &text) {
        for (const auto &[name, v] : names)
          if (name == text)
            value = v;
      });
    }

    /**
     * The pattern of a vector expression: 1 to @p max_components
     * components separated by ';' (FunctionParser's own Convert uses this
     * form); parse_expression() checks the exact count for the entry. An
     * @p optional entry may be empty.
     */
    Patterns::List
    expression_pattern(const unsigned int max_components,
                       const bool         optional = false);

    /**
     * The pattern of "name: value; name: value; ..." with names that are
     * any text without ':' or ';' and values of @p value_pattern; it
     * converts to std::vector<std::pair<std::string, T>> (names may repeat:
     * the caller says whether they may).
     */
    Patterns::List
    named_list_pattern(const Patterns::PatternBase &value_pattern);

    /**
     * Evaluate a constant expression such as "sqrt(0.01*0.5/pi)".
     */
    double
    evaluate_constant(const std::string &expression,
                      const std::string &parameter);

    /**
     * Split "a; b; c" at @p separator and trim white space.
     */
    std::vector<std::string>
    split(const std::string &text, const char separator);

    /**
     * The finite number that is all of @p text, or nothing: the one number
     * parser of scene files and mesh files (each caller words its error).
     */
    std::optional<double>
    number(const std::string &text);

    /**
     * Whether every ';'-separated part of @p expression is a number: a
     * function written this way is the same everywhere (and at every time).
     */
    bool
    numbers_only(const std::string &expression);

    /**
     * A finite double from @p text (white space around it allowed), or an
     * error naming @p parameter.
     */
    double
    to_double(const std::string &text, const std::string &parameter);

    /**
     * Turn an exception's text into one line: deal.II's messages span many
     * lines and carry a stack trace the user has no use for.
     */
    std::string
    one_line(const std::string &text);

    /**
     * @p value in a message: six significant digits, exponent where it
     * needs one ("1e-300", "0.002", "2.5e+09"); std::to_string prints
     * fixed six decimals (1e-300 as "0.000000").
     */
    std::string
    format(double value);

    /**
     * Shorten values echoed in a message ('...' or <...>) to 200 bytes and
     * the whole message to 1000: a 6 MB expression is not a message.
     */
    std::string
    cap(const std::string &line);

    /**
     * A name of a material or interface: 1 to 100 bytes of valid UTF-8
     * without control characters (it goes into summary.json and file
     * names), or an error naming @p parameter.
     */
    void
    check_name(const std::string &name, const std::string &parameter);
  } // namespace input



  /** A point in a message: "(x, y)" or "(x, y, z)". */
  template <int dim>
  std::string
  point_text(const Point<dim> &point)
  {
    std::string text = "(";
    for (unsigned int d = 0; d < dim; ++d)
      text += (d ? ", " : "") + input::format(point[d]);
    return text + ")";
  }
} // namespace knee_contact

#endif
