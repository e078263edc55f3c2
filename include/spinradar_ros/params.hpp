#pragma once
// Core config structs <-> ROS parameters and dynamic_reconfigure configs, generically over the
// structs' visit() (the X-macro lists in spinradar/core/params.hpp are the single definition).
#include <stdexcept>
#include <string>
#include <type_traits>

#include <boost/any.hpp>
#include <ros/node_handle.h>

#include "spinradar/core/param_macros.hpp"

namespace spinradar_ros {

template <class>
inline constexpr bool kUnsupportedParamType = false;

/// Reads every field of `cfg` that is set under `nh` (a nodelet's private handle); unset
/// fields keep their current value (the struct's in-class default). Does not validate: call
/// cfg.validate() after. Throws std::invalid_argument naming the parameter on a wrong type.
template <class Config>
void loadParams(const ros::NodeHandle& nh, Config& cfg) {
  cfg.visit([&nh](const spinradar::ParamMeta& m, auto& value) {
    using T = std::decay_t<decltype(value)>;
    static_assert(std::is_same_v<T, int> || std::is_same_v<T, double> ||
                      std::is_same_v<T, bool> || std::is_same_v<T, std::string>,
                  "parameter type without a ROS parameter equivalent");
    if (!nh.hasParam(m.name)) return;
    T v{};
    if (!nh.getParam(m.name, v))  // int is accepted for double, nothing else converts
      throw std::invalid_argument("ROS parameter '" + nh.resolveName(m.name) +
                                  "' has the wrong type (expected " +
                                  (std::is_same_v<T, std::string> ? "string"
                                   : std::is_same_v<T, bool>      ? "bool"
                                   : std::is_same_v<T, int>       ? "int"
                                                                  : "double") +
                                  ")");
    value = v;
  });
}

/// Copies the fields a generated dynamic_reconfigure config (e.g. spinradar::FeatureNodeletConfig)
/// has into `cfg`, matched by name; fields the config does not carry are left alone.
template <class DrConfig, class Config>
void fromReconfigure(const DrConfig& dr, Config& cfg) {
  const auto& descriptions = DrConfig::__getParamDescriptions__();
  cfg.visit([&](const spinradar::ParamMeta& m, auto& value) {
    using T = std::decay_t<decltype(value)>;
    for (const auto& d : descriptions) {
      if (d->name != m.name) continue;
      boost::any any;
      d->getValue(dr, any);
      value = boost::any_cast<T>(any);  // cfg types follow the X-macro types one to one
      return;
    }
  });
}

/// Applies a dynamic_reconfigure update to a copy of `cfg`; commits it only when validate()
/// accepts it. Returns the validation error ("" on success).
template <class DrConfig, class Config>
std::string applyReconfigure(const DrConfig& dr, Config& cfg) {
  Config next = cfg;
  fromReconfigure(dr, next);
  try {
    next.validate();
  } catch (const std::exception& e) {
    return e.what();
  }
  cfg = next;
  return {};
}

}  // namespace spinradar_ros
