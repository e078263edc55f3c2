#pragma once
// Glint and azimuth jitter of the rendering (physics "glint", "glint_across", "glint_along",
// "azimuth_jitter"): per-scan random draws hashed from (seed, scan, scatterer or row), so that
// bucketing and rendering see the same shift and every thread the same scan.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "simulator_impl.hpp"

namespace spinradar::sim::detail {

/// Shift of every scatterer's scattering centre in one scan.
class Glint {
 public:
  Glint(const ExtraEffects& fx, uint64_t seed, uint64_t scan_key, double mx, double my)
      : fx_(fx), key_(Rng::splitmix(seed ^ (scan_key * 0xD1B54A32D192ED03ull))), mx_(mx), my_(my),
        aniso_(fx.glint_across > 0 || fx.glint_along > 0) {}

  void apply(uint32_t id, double& x, double& y) const {
    // Isotropic: where on an extended object (facade relief, bush, car) the return comes from
    // changes with the aspect.
    if (fx_.glint > 0) {
      const double m = fx_.glint * radius(id, 1);
      const double t = 2 * M_PI * hashUniform(key_, id, 2);
      x += m * std::cos(t);
      y += m * std::sin(t);
    }
    if (!aniso_) return;
    // Anisotropic: separate draws along and across the line of sight from the scan's middle
    // pose (the real spread is larger across the beam than along it).
    const double dx = x - mx_, dy = y - my_, r = std::hypot(dx, dy);
    if (r < 1e-6) return;
    const double m = radius(id, 3), t = 2 * M_PI * hashUniform(key_, id, 4);
    const double along = fx_.glint_along * m * std::cos(t), across = fx_.glint_across * m * std::sin(t);
    const double ux = dx / r, uy = dy / r;
    x += along * ux - across * uy;
    y += along * uy + across * ux;
  }

 private:
  double radius(uint32_t id, uint64_t k) const {  // Box-Muller radius
    return std::sqrt(-2.0 * std::log(std::max(hashUniform(key_, id, k), 1e-300)));
  }
  const ExtraEffects& fx_;
  uint64_t key_;
  double mx_, my_;
  bool aniso_;
};

/// Error of the true beam angle of row `a` (rad): independent per row and scan.
inline double azimuthJitter(const ExtraEffects& fx, uint64_t seed, uint64_t scan_key, int a) {
  const uint64_t k = Rng::splitmix(seed ^ (scan_key * 0xA24BAED4963EE407ull));
  const double u1 = hashUniform(k, uint64_t(a), 5), u2 = hashUniform(k, uint64_t(a), 6);
  return fx.azimuth_jitter * std::sqrt(-2.0 * std::log(std::max(u1, 1e-300))) * std::cos(2 * M_PI * u2);
}

}  // namespace spinradar::sim::detail
