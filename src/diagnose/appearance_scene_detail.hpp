// Internals of the appearance stage's own reference scene (appearance_scene.cpp and its CLEAN
// deconvolution, appearance_scene_clean.cpp). Not part of the public interface.
#pragma once

#include <vector>

#include "spinradar/core/polar_scan.hpp"
#include "spinradar/diagnose/appearance.hpp"
#include "spinradar/sim/sensor_config.hpp"
#include "spinradar/sim/scene.hpp"

namespace spinradar::diagnose::scene_detail {

/// Count -> received power in dB, the inverse of the model's quantiser.
double countToDb(double c, const sim::SensorConfig& s);
/// Gain chain of a 0 dBsm point return at range r (dB).
double pointGainDb(double r, const sim::SensorConfig& s);
/// The row each row of the scene is read from (-1: none); masked rows borrow a fit row a quarter
/// turn away, so held-out rows are never read.
std::vector<int> sourceRows(const PolarScan& scan);
/// The model's two-way azimuth response in power at 0..span rows, read off a render.
std::vector<double> beamProfile(const sim::SensorConfig& s);
/// That profile at a fractional row offset x (log-linear between rows, 0 beyond it).
double beamAt(const std::vector<double>& kern, double x);

/// The model's range point spread in power at a fractional bin offset x, peak 1 (the render
/// model's mainlobe and window sidelobes, render_model.cpp).
double rangePsf(const sim::SensorConfig& s, double x);

/// A scatterer of the one-point scene: row, bin, sub-row offset and power over the gain chain.
struct SceneScatterer {
  int r = 0, b = 0;
  double delta = 0, p = 0;
  double bin_offset = 0;  ///< sub-bin range offset (scene_range_subbin), bins
};
/// Strengths of the one-point scene refined jointly along azimuth, positions held
/// (appearance_scene_refine.cpp): `passes` multiplicative NNLS updates of the model's azimuth
/// response `kern` against the recording's power over `floor_q` on the rows `src` gives.
void refineAlongAzimuth(const PolarScan& scan, const sim::SensorConfig& s,
                        const std::vector<int>& src, const std::vector<int>& floor_q,
                        const std::vector<double>& kern, std::vector<SceneScatterer>& sc,
                        int passes);

/// The CLEAN scene of one scan: `src` from sourceRows, `floor_q` the count of each bin's upper
/// quartile, `per_db` the counts per dB of the margin.
sim::World cleanWorld(const PolarScan& scan, const sim::SensorConfig& s,
                      const std::vector<int>& src, const std::vector<int>& floor_q, double per_db,
                      const AppearanceOptions& opt);

}  // namespace spinradar::diagnose::scene_detail
