/// \file cli_checks.hpp
/// The command-line checks every example program shares (CLI11 only, no parafsi
/// headers): the finite-number validator and `parse`, which puts it on every
/// floating-point option first, so NaN and ±inf are refused naming the flag
/// ("--t-end: value nan is not a finite number") whatever ranges the program adds.
#pragma once
#include <cmath>
#include <string>

#include <CLI/CLI.hpp>

namespace examples {

/// Validator for floating-point options: refuses NaN and ±inf, naming the value (CLI11
/// prefixes the option's name). CLI::Range lets NaN through (every comparison with NaN
/// is false); `parse` adds this validator to every floating-point option.
inline const CLI::Validator finite{[](std::string& s) {
  double v = 0;
  if (!CLI::detail::lexical_cast(s, v)) return "'" + s + "' is not a number";
  if (!std::isfinite(v)) return "value " + s + " is not a finite number";
  return std::string();
                                   },
                                   ""};

/// Every floating-point option of `app` (CLI11 type name FLOAT, followed by its
/// validators' descriptions) refuses non-finite values.
inline void require_finite_numbers(CLI::App& app) {
  for (CLI::Option* o : app.get_options()) {
    const std::string type = o->get_type_name();
    if (type == "FLOAT" || type.rfind("FLOAT:", 0) == 0) o->check(finite);
  }
}

/// Parse argv (non-finite numbers refused first); on --help prints usage and returns 0
/// through `exit_code`, on a bad flag prints the message and returns non-zero. Returns
/// true if the run goes on.
inline bool parse(CLI::App& app, int argc, char** argv, int& exit_code) {
  require_finite_numbers(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    exit_code = app.exit(e);
    return false;
  }
  return true;
}

}  // namespace examples
