#include "pipeline_options.hpp"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include <yaml-cpp/yaml.h>

namespace spinradar::cli {

namespace {

std::string dashed(std::string s) {
  std::replace(s.begin(), s.end(), '_', '-');
  return s;
}

template <class T>
std::string defaultText(const T& v) {
  std::ostringstream o;
  if constexpr (std::is_same_v<T, bool>) o << (v ? "true" : "false");
  else o << v;
  return o.str();
}

template <class Group>
bool hasParam(const Group& g, const std::string& name) {
  bool found = false;
  g.visit([&](const ParamMeta& m, const auto&) { found = found || name == m.name; });
  return found;
}

void applyMap(const YAML::Node& map, PipelineConfig& cfg, const std::string& path,
              const std::string& prefix, const ExtraParamSetter& extra) {
  std::map<std::string, int> seen;  // YAML keeps one of two equal keys silently: refuse them
  for (const auto& kv : map) {
    const std::string key = kv.first.as<std::string>();
    const std::string where = path + ":" + std::to_string(kv.first.Mark().line + 1);
    const auto [it, fresh] = seen.emplace(key, kv.first.Mark().line + 1);
    if (!fresh)
      throw std::invalid_argument(where + ": '" + prefix + key + "' given twice (also on line " +
                                  std::to_string(it->second) + ")");
    const YAML::Node& v = kv.second;
    if (v.IsMap()) {
      if (!prefix.empty() || (key != "detector" && key != "features" && key != "estimator"))
        throw std::invalid_argument(where + ": '" + prefix + key +
                                    "' is not a parameter group (detector, features, estimator)");
      // Group members must belong to that group, so a typo does not silently land elsewhere.
      for (const auto& member : v) {
        const std::string name = member.first.as<std::string>();
        const bool ok = key == "detector"   ? hasParam(cfg.detector, name)
                        : key == "features" ? hasParam(cfg.features, name)
                                            : hasParam(cfg.estimator, name);
        if (!ok)
          throw std::invalid_argument(path + ":" + std::to_string(member.first.Mark().line + 1) +
                                      ": unknown " + key + " parameter '" + name + "'");
      }
      applyMap(v, cfg, path, key + ".", extra);
      continue;
    }
    if (!v.IsScalar())
      throw std::invalid_argument(where + ": parameter '" + key + "' needs a single value");
    if (prefix.empty() && extra && extra(key, v.Scalar(), where)) continue;
    setPipelineParam(cfg, key, v.Scalar(), where);
  }
}

}  // namespace

void setPipelineParam(PipelineConfig& cfg, const std::string& name, const std::string& value,
                      const std::string& where) {
  bool found = false;
  cfg.visit([&](const ParamMeta& m, auto& field) {
    if (found || name != m.name) return;
    using T = std::decay_t<decltype(field)>;
    field = parseValue<T>(value, where, m.name);
    found = true;
  });
  if (!found) throw std::invalid_argument(where + ": unknown parameter '" + name + "'");
}

void loadPipelineYaml(const std::string& path, PipelineConfig& cfg, const ExtraParamSetter& extra) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw std::runtime_error(path + ": cannot open the configuration file");
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (root.IsNull()) return;
  if (!root.IsMap())
    throw std::runtime_error(path + ": expected a map of parameter names to values");
  try {
    applyMap(root, cfg, path, "", extra);
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(path + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

void PipelineOptions::add(CLI::App& app, const std::string& group) {
  app.add_option("--config", config_path_,
                 "YAML file of pipeline parameters (flat or grouped by detector/features/"
                 "estimator); options given on the command line override it")
      ->check(CLI::ExistingFile);
  PipelineConfig defaults;
  defaults.visit([&](const ParamMeta& m, const auto& v) {
    using T = std::decay_t<decltype(v)>;
    std::string names = "--" + std::string(m.name);
    if (dashed(m.name) != m.name) names += ",--" + dashed(m.name);
    std::string help = m.doc;
    if (m.unit[0]) help += std::string(" [") + m.unit + "]";
    help += " (default " + defaultText(v);
    if constexpr (std::is_arithmetic_v<T> && !std::is_same_v<T, bool>)
      help += ", range " + defaultText(m.min) + " .. " + defaultText(m.max);
    help += ")";
    auto* opt = app.add_option(names, values_[m.name], help)->group(group);
    if constexpr (std::is_same_v<T, std::string>) opt->type_name("TEXT");
    else if constexpr (std::is_same_v<T, bool>) opt->type_name("BOOL");
    else if constexpr (std::is_integral_v<T>) opt->type_name("INT");
    else opt->type_name("FLOAT");
    options_[m.name] = opt;
  });
}

PipelineConfig PipelineOptions::resolve() const {
  PipelineConfig cfg;
  if (!config_path_.empty()) loadPipelineYaml(config_path_, cfg, extra_);
  for (const auto& [name, opt] : options_)
    if (opt->count() > 0) setPipelineParam(cfg, name, values_.at(name), "option --" + name);
  for (const auto& [name, value] : forced_) setPipelineParam(cfg, name, value, "--" + name);
  cfg.validate();
  return cfg;
}

}  // namespace spinradar::cli
