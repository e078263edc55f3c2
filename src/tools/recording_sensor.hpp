#pragma once
// The sensor description a recording carries: `simulate` (and `capture replay`) write
// sensor.json beside radar/, so a recording made with another sensor model (RADIATE's 0.174 m
// range bins, say) is read at its own bin size instead of the format's default.
#include <optional>
#include <string>

namespace spinradar::cli {

struct RecordedSensor {
  std::string path;         ///< the sensor.json read
  double range_resolution;  ///< m per bin, checked by the sensor model's own validation
};

/// sensor.json in `input`, or beside it when `input` is the recording's radar/ folder; nullopt
/// when there is none. A file that is there but malformed is an error naming it.
std::optional<RecordedSensor> recordedSensor(const std::string& input);

}  // namespace spinradar::cli
