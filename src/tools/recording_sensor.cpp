#include "recording_sensor.hpp"

#include <filesystem>

#include "spinradar/sim/sensor_config.hpp"

namespace spinradar::cli {

std::optional<RecordedSensor> recordedSensor(const std::string& input) {
  namespace fs = std::filesystem;
  const fs::path in(input);
  for (const fs::path& dir : {in, in.filename() == "radar" ? in.parent_path() : fs::path()}) {
    if (dir.empty()) continue;
    const fs::path sj = dir / "sensor.json";
    if (!fs::is_regular_file(sj)) continue;
    const sim::SensorConfig s = sim::SensorConfig::load(sj.string());  // validated, errors named
    return RecordedSensor{sj.string(), s.range_resolution};
  }
  return std::nullopt;
}

}  // namespace spinradar::cli
