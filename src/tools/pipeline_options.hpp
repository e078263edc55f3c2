#pragma once
// CLI options for every pipeline parameter, generated from PipelineConfig::visit(), plus
// `--config FILE.yaml`. Precedence: built-in defaults < YAML file < command-line options.
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <limits>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>

#include <CLI/CLI.hpp>

#include "spinradar/core/params.hpp"

namespace spinradar::cli {

/// Parameters of a YAML file outside the pipeline's (e.g. `localize`'s localizer and RSD ones):
/// returns true when it took `name`.
using ExtraParamSetter =
    std::function<bool(const std::string& name, const std::string& value, const std::string& where)>;

template <class T>
T parseValue(const std::string& text, const std::string& where, const char* name) {
  auto bad = [&](const std::string& why) {
    return std::invalid_argument(where + ": parameter '" + name + "': '" + text + "' " + why);
  };
  if constexpr (std::is_same_v<T, std::string>) {
    return text;
  } else if constexpr (std::is_same_v<T, bool>) {
    if (text == "true" || text == "1" || text == "on" || text == "yes") return true;
    if (text == "false" || text == "0" || text == "off" || text == "no") return false;
    throw bad("is not a boolean (true/false)");
  } else if constexpr (std::is_integral_v<T>) {
    errno = 0;
    char* end = nullptr;
    const long long v = std::strtoll(text.c_str(), &end, 10);
    if (text.empty() || *end != '\0') throw bad("is not an integer");
    if (errno == ERANGE || v < static_cast<long long>(std::numeric_limits<T>::min()) ||
        (v > 0 && static_cast<unsigned long long>(v) > static_cast<unsigned long long>(std::numeric_limits<T>::max())))
      throw bad("is out of range for an integer parameter");
    return static_cast<T>(v);
  } else {
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0' || errno == ERANGE) throw bad("is not a number");
    if (!std::isfinite(v)) throw bad("is not a finite number (NaN and infinities are never valid)");
    return static_cast<T>(v);
  }
}

/// Sets the parameter `name` of any X-macro config from text; false when it has none of that name.
template <class Config>
bool setParamByName(Config& cfg, const std::string& name, const std::string& value,
                    const std::string& where) {
  bool found = false;
  cfg.visit([&](const ParamMeta& m, auto& field) {
    if (found || name != m.name) return;
    field = parseValue<std::decay_t<decltype(field)>>(value, where, m.name);
    found = true;
  });
  return found;
}

class PipelineOptions {
 public:
  /// Registers `--<name>` (and `--<name-with-dashes>`) for each parameter and `--config`,
  /// under the option group `group`.
  void add(CLI::App& app, const std::string& group = "Pipeline parameters");
  /// Defaults, then the YAML file (if given), then the options given; validated.
  PipelineConfig resolve() const;
  /// Forces a parameter as if given on the command line (e.g. bench sweeping estimators).
  void set(const std::string& name, const std::string& value) { forced_[name] = value; }
  /// Takes the YAML keys that are not pipeline parameters (before they count as unknown).
  void setExtraParams(ExtraParamSetter extra) { extra_ = std::move(extra); }
  /// The --config file given ("" when none).
  const std::string& configPath() const { return config_path_; }

 private:
  std::map<std::string, std::string> values_;
  std::map<std::string, CLI::Option*> options_;
  std::map<std::string, std::string> forced_;
  std::string config_path_;
  ExtraParamSetter extra_;
};

/// Sets the parameter `name` from text. `where` prefixes error messages (e.g. "option --zq" or
/// "cfg.yaml:3"). Throws std::invalid_argument for unknown names and malformed values.
void setPipelineParam(PipelineConfig& cfg, const std::string& name, const std::string& value,
                      const std::string& where);

/// Applies a YAML file: a flat map `name: value` or grouped under `detector:`, `features:`,
/// `estimator:` (a scalar `detector:`/`estimator:` is the parameter of that name). Errors name
/// the file, the line and the key.
void loadPipelineYaml(const std::string& path, PipelineConfig& cfg,
                      const ExtraParamSetter& extra = {});

}  // namespace spinradar::cli
