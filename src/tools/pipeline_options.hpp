#pragma once
// CLI options for every pipeline parameter, generated from PipelineConfig::visit(), plus
// `--config FILE.yaml`. Precedence: built-in defaults < YAML file < command-line options.
#include <map>
#include <string>

#include <CLI/CLI.hpp>

#include "spinradar/core/params.hpp"

namespace spinradar::cli {

class PipelineOptions {
 public:
  /// Registers `--<name>` (and `--<name-with-dashes>`) for each parameter and `--config`,
  /// under the option group `group`.
  void add(CLI::App& app, const std::string& group = "Pipeline parameters");
  /// Defaults, then the YAML file (if given), then the options given; validated.
  PipelineConfig resolve() const;
  /// Forces a parameter as if given on the command line (e.g. bench sweeping estimators).
  void set(const std::string& name, const std::string& value) { forced_[name] = value; }

 private:
  std::map<std::string, std::string> values_;
  std::map<std::string, CLI::Option*> options_;
  std::map<std::string, std::string> forced_;
  std::string config_path_;
};

/// Sets the parameter `name` from text. `where` prefixes error messages (e.g. "option --zq" or
/// "cfg.yaml:3"). Throws std::invalid_argument for unknown names and malformed values.
void setPipelineParam(PipelineConfig& cfg, const std::string& name, const std::string& value,
                      const std::string& where);

/// Applies a YAML file: a flat map `name: value` or grouped under `detector:`, `features:`,
/// `estimator:` (a scalar `detector:`/`estimator:` is the parameter of that name). Errors name
/// the file, the line and the key.
void loadPipelineYaml(const std::string& path, PipelineConfig& cfg);

}  // namespace spinradar::cli
