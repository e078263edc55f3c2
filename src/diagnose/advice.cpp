#include "spinradar/diagnose/advice.hpp"

#include <algorithm>
#include <utility>

namespace spinradar::diagnose {

std::string separatingDrive(Effect a, Effect b) {
  using E = Effect;
  if (static_cast<int>(a) > static_cast<int>(b)) std::swap(a, b);
  const auto is = [&](E x, E y) { return a == x && b == y; };
  if (is(E::Doppler, E::RangeOffset))
    return "at constant speed with features on one side a Doppler shift is a constant range "
           "offset; drive with speed changes (accelerate / brake) and keep targets both ahead "
           "and behind (the Doppler shift changes sign, a range offset does not).";
  if (is(E::Doppler, E::TimestampOffset))
    return "in straight driving both move returns along the track; turns separate them "
           "(a latency also rotates the scan by yaw rate x latency, Doppler has no yaw term), "
           "as do targets abeam (latency shifts them tangentially, Doppler only radially).";
  if (is(E::MotionDistortion, E::TimestampOffset))
    return "both scale with speed; speed changes within the drive and targets all around the "
           "sensor separate them (motion distortion grows with the time inside the sweep, a "
           "latency is the same for every azimuth); an out-and-back drive flips both.";
  if (is(E::MotionDistortion, E::Doppler))
    return "both scale with speed; targets ahead vs behind and vs abeam separate them "
           "(Doppler is radial, cos(azimuth); motion distortion is a shear growing with the "
           "time in the sweep and tears at the scan seam), as do speed changes.";
  if (is(E::MotionDistortion, E::AzimuthOffset))
    return "during turns in one direction the rotational distortion looks like an azimuth "
           "offset; turn both ways (the distortion flips sign with the yaw rate, the encoder "
           "offset does not).";
  if (is(E::TimestampOffset, E::AzimuthOffset))
    return "at constant yaw rate a latency rotates every scan by yaw rate x latency, like an "
           "encoder offset; turn both ways and drive straight stretches.";
  if (is(E::TimestampOffset, E::RangeOffset))
    return "with targets only ahead a latency shortens ranges like a negative range offset; "
           "drive past targets so they are seen ahead, abeam and behind, with speed changes.";
  if (is(E::MotionDistortion, E::RangeOffset))
    return "with few azimuths covered the shear looks like a constant; use targets all around "
           "the sensor and vary the speed.";
  if (is(E::Doppler, E::AzimuthOffset))
    return "use targets at several ranges and bearings: Doppler is radial, the encoder offset "
           "tangential.";
  return "use a drive with speed changes, turns both ways, and targets all around the sensor.";
}

std::string revealingSplit(Effect e) {
  switch (e) {
    case Effect::MotionDistortion:
      return "map and test must see the targets at other times in the sweep or at other "
             "velocities: an out-and-back drive (--map-split out-back) or speed changes.";
    case Effect::Doppler:
      return "map and test must see the targets at other radial velocities: an out-and-back "
             "drive (--map-split out-back) or a speed change between the halves.";
    case Effect::TimestampOffset:
      return "map and test must move or turn differently: an out-and-back drive "
             "(--map-split out-back), speed changes, or turns of opposite sign in the halves.";
    case Effect::AzimuthOffset:
      return "map and test must see the targets from other places or headings: turns, "
             "targets passed abeam, or an out-and-back drive (--map-split out-back).";
    case Effect::RangeOffset:
      return "map and test must see the same targets from other directions: an out-and-back "
             "drive (--map-split out-back) or targets passed (ahead in one half, abeam or "
             "behind in the other).";
  }
  return "";
}

std::string signatureOf(Effect e) {
  switch (e) {
    case Effect::MotionDistortion:
      return "displacement -v * tau(azimuth): a shear growing over the sweep with a tear at the "
             "scan seam, plus an azimuth error yaw_rate * tau";
    case Effect::Doppler:
      return "purely radial range shift -beta * (v . u): cos(azimuth) pattern, scales with speed";
    case Effect::TimestampOffset:
      return "the whole scan displaced by v * dt and rotated by yaw_rate * dt";
    case Effect::AzimuthOffset:
      return "constant azimuth error at every range (tangential r * offset)";
    case Effect::RangeOffset:
      return "constant range error at every azimuth and speed";
  }
  return "";
}

}  // namespace spinradar::diagnose
