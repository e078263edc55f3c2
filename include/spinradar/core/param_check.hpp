#pragma once
// Generic range checks over a config's visit(): every numeric field must lie in [min, max].
#include <stdexcept>
#include <string>
#include <type_traits>

#include "spinradar/core/param_macros.hpp"

namespace spinradar {

template <class Config>
void checkParamRanges(const Config& cfg, const char* group) {
  cfg.visit([group](const ParamMeta& m, const auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>) {
      if (value < m.min || value > m.max)
        throw std::invalid_argument(std::string(group) + " parameter '" + m.name + "' = " +
                                    std::to_string(value) + " is outside [" +
                                    std::to_string(m.min) + ", " + std::to_string(m.max) + "]" +
                                    (m.unit[0] ? std::string(" ") + m.unit : std::string()));
    }
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
