// `spinradar params`: lists every pipeline and sensor parameter (the README table source).
#include <iostream>
#include <sstream>
#include <type_traits>

#include "command.hpp"
#include "spinradar/driver/driver_config.hpp"
#include "spinradar/localization/localizer.hpp"
#include "spinradar/core/params.hpp"
#include "spinradar/localization/rsd.hpp"
#include "spinradar/sim/sensor_config.hpp"

namespace {

template <class Config>
void printTable(const char* group, const Config& cfg) {
  cfg.visit([group](const spinradar::ParamMeta& m, const auto& v) {
    using T = std::decay_t<decltype(v)>;
    std::ostringstream def, range;
    if constexpr (std::is_same_v<T, bool>) {
      def << (v ? "true" : "false");
    } else if constexpr (std::is_same_v<T, std::string>) {
      def << '"' << v << '"';
    } else {
      def << v;
      range << m.min << " .. " << m.max;
    }
    std::cout << "| " << group << " | `" << m.name << "` | " << def.str() << " | " << range.str()
              << " | " << m.unit << " | " << m.doc << " |\n";
  });
}

}  // namespace

SPINRADAR_COMMAND("params", "Print every parameter with default, range, unit and doc (Markdown)",
                  [](CLI::App& app) {
                    app.callback([] {
                      spinradar::PipelineConfig c;
                      std::cout << "| group | parameter | default | range | unit | description |\n"
                                << "|---|---|---|---|---|---|\n";
                      printTable("detector", c.detector);
                      printTable("features", c.features);
                      printTable("estimator", c.estimator);
                      printTable("localizer", spinradar::LocalizerConfig{});
                      printTable("rsd", spinradar::RsdConfig{});
                      printTable("driver", spinradar::DriverConfig{});
                      printTable("sim sensor", spinradar::sim::SensorConfig{});
                    });
                  });
