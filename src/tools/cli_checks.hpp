#pragma once
// Option checks shared by every subcommand: numbers must be finite (NaN and infinities are never
// valid, added to every numeric option by main.cpp), ranges are printed readably (CLI11's own
// PositiveNumber prints 1.79e308 with 300 digits), counts must be counts.
#include <cmath>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

#include "spinradar/core/param_check.hpp"

namespace spinradar::cli {

namespace detail {
/// Parses the whole text as a double; false when it is not a number.
inline bool number(const std::string& text, double& v) {
  char* end = nullptr;
  v = std::strtod(text.c_str(), &end);
  return !text.empty() && end != text.c_str() && *end == '\0';
}
}  // namespace detail

/// Rejects NaN and infinities ("nan", "inf", "1e999"); leaves non-numbers to the option's parser.
inline CLI::Validator finiteNumber() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        double v = 0;
        if (detail::number(in, v) && !std::isfinite(v))
          return "'" + in + "' is not a finite number";
        return {};
      },
      "", "FINITE");
}

/// lo <= value <= hi (either bound may be +-infinity for "none"), finite, message readable:
/// "--threads: -1 is below the minimum 0".
inline CLI::Validator inRange(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& in) -> std::string {
        double v = 0;
        if (!detail::number(in, v)) return "'" + in + "' is not a number";
        if (!std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (v < lo) return in + " is below the minimum " + readableNumber(lo);
        if (v > hi) return in + " is above the maximum " + readableNumber(hi);
        return {};
      },
      "", "RANGE");
}
inline CLI::Validator atLeast(double lo) { return inRange(lo, HUGE_VAL); }
/// Strictly positive.
inline CLI::Validator positive() {
  return CLI::Validator(
      [](std::string& in) -> std::string {
        double v = 0;
        if (!detail::number(in, v)) return "'" + in + "' is not a number";
        if (!std::isfinite(v)) return "'" + in + "' is not a finite number";
        if (!(v > 0)) return in + " must be greater than 0";
        return {};
      },
      "", "POSITIVE");
}

/// Adds finiteNumber() to every numeric option of `app` and of all its subcommands.
inline void requireFiniteNumbers(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string t = opt->get_type_name();
    if (t.find("FLOAT") != std::string::npos || t.find("INT") != std::string::npos ||
        t.find("NUMBER") != std::string::npos)
      opt->check(finiteNumber());
  }
  for (CLI::App* sub : app.get_subcommands({})) requireFiniteNumbers(*sub);
}

}  // namespace spinradar::cli
