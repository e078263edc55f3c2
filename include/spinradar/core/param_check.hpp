#pragma once
// Generic range checks over a config's visit(): every numeric field must be finite (NaN and
// infinities are never valid) and lie in [min, max]; numbers are printed readably (%g).
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>

#include "spinradar/core/param_macros.hpp"

namespace spinradar {

/// A number as a person reads it: "0.0438", "1e+06", "2147483647"; "max"/"-max" for the
/// limits of double that stand for "no bound".
inline std::string readableNumber(double v) {
  if (v >= std::numeric_limits<double>::max() * 0.5) return "max";
  if (v <= -std::numeric_limits<double>::max() * 0.5) return "-max";
  char buf[32];
  std::snprintf(buf, sizeof buf, std::fabs(v) < 1e15 && v == std::floor(v) ? "%.0f" : "%.6g", v);
  return buf;
}

/// Throws std::invalid_argument "<group> parameter '<name>' = <v> is outside [lo, hi] <unit>"
/// (or "... is not a finite number").
inline void checkParamValue(double value, const ParamMeta& m, const char* group) {
  const std::string head = std::string(group) + " parameter '" + m.name + "' = ";
  if (!std::isfinite(value))
    throw std::invalid_argument(head + readableNumber(value) + " is not a finite number");
  if (!(value >= m.min && value <= m.max))
    throw std::invalid_argument(head + readableNumber(value) + " is outside [" +
                                readableNumber(m.min) + ", " + readableNumber(m.max) + "]" +
                                (m.unit[0] ? std::string(" ") + m.unit : std::string()));
}

template <class Config>
void checkParamRanges(const Config& cfg, const char* group) {
  cfg.visit([group](const ParamMeta& m, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
      checkParamValue(static_cast<double>(value), m, group);
  });
}

inline void checkOneOf(const std::string& value, std::initializer_list<const char*> allowed,
                       const char* name) {
  std::string list;
  for (const char* a : allowed) {
    if (value == a) return;
    list += list.empty() ? a : std::string(", ") + a;
  }
  throw std::invalid_argument(std::string("parameter '") + name + "' = '" + value +
                              "' is not one of: " + list);
}

}  // namespace spinradar
