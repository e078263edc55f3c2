// Appearance stage: the glint terms (glint_terms.hpp) added to the catalogue's findings.
#include <algorithm>
#include <cstdio>
#include <string>

#include "appearance_detail.hpp"
#include "spinradar/diagnose/glint_terms.hpp"

namespace spinradar::diagnose::detail {

void appendGlint(const std::vector<PolarScan>& real, sim::SensorConfig& cur,
                 sim::PhysicsConfig& phys, const AppearanceOptions& opt, AppearanceReport& rep,
                 int stride) {
  GlintTermsOptions go;
  go.ref.seed = opt.seed;
  // Pairs `stride` rotations apart, in the recording and the reference alike (the motion between
  // the scans of a pair adds spread); the alignment search widens with the motion.
  go.ref.spread.stride = std::max(stride, 1);
  go.ref.spread.search *= go.ref.spread.stride;
  go.ref.spread.search_yaw_deg *= go.ref.spread.stride;
  go.z_min = opt.z_min;
  // The reference drives the city route: with the drive's physics (motion distortion, Doppler,
  // movers), as the real samples were recorded and as `spinradar spread` / `realism` and the
  // evaluation matrix re-simulate them; without it the terms absorb that spread (RADIATE: across
  // 0.086 m, along 0.081 m, jitter 0.32 deg, which overshot the re-simulated spread 20-40 %).
  sim::PhysicsConfig drive = phys;
  drive.motion_distortion = true;
  if (drive.doppler == 0) drive.doppler = 0.049;
  drive.moving_objects = true;
  const GlintTermsFit g = fitGlintTerms(real, cur, drive, go);
  struct Entry {
    const char* effect;
    const GlintTerm& t;
    double real, before, after;  // the spread figure the term moves (pooled), m
  };
  const Entry entries[3] = {
      {"glint across the beam", g.across, g.real.all.tangential, g.base.all.tangential, g.after.all.tangential},
      {"glint along the beam", g.along, g.real.all.radial, g.base.all.radial, g.after.all.radial},
      {"azimuth jitter (across, growing with range)", g.jitter, g.real.all.tangential,
       g.base.all.tangential, g.after.all.tangential}};
  for (const auto& e : entries) {
    auto it = cur.physics.find(e.t.key);
    const double base = it == cur.physics.end() ? 0.0 : it->second;
    AppearanceFinding f = makeFinding(e.effect, e.t.key, e.t.unit, base, e.t.value, e.t.stddev,
                                      e.t.size, e.t.size_unit, e.t.named, opt.z_min);
    f.z = e.t.z, f.named = e.t.named, f.verdict = e.t.verdict;
    if (g.measured) f.gap_before = e.real - e.before, f.gap_after = e.real - e.after;
    rep.findings.push_back(f);
  }
  if (!g.measured) {
    rep.notes.push_back(stride > 1 ? "Glint not identifiable: the fit part has no two scans " +
                                         std::to_string(stride) + " rotations apart."
                                   : "Glint not identifiable: the fit part has no two distinct consecutive scans.");
    return;
  }
  for (const GlintTerm* t : {&g.across, &g.along, &g.jitter})
    if (t->verdict != "not identifiable") cur.physics.erase(t->key);
  for (const auto& [k, v] : g.named()) cur.physics[k] = v;
  char buf[700];
  std::snprintf(buf, sizeof buf,
                "Glint (fit part; pairs %d rotation(s) apart, reference too): returns matched "
                "between scans spread %.3f m across the beam "
                "(%.3f along; %d pairs), the model %.3f (%.3f) without glint terms and %.3f (%.3f) "
                "with the named ones: glint_across %.3f +- %.3f m (%s), glint_along %.3f +- %.3f m "
                "(%s), azimuth_jitter %.3f +- %.3f deg (%s); reference: %d x %d scans "
                "(%d apart) of the %s route.",
                go.ref.spread.stride, g.real.all.tangential, g.real.all.radial, g.real.pairs, g.base.all.tangential,
                g.base.all.radial, g.after.all.tangential, g.after.all.radial, g.across.value,
                g.across.stddev, g.across.verdict.c_str(), g.along.value, g.along.stddev,
                g.along.verdict.c_str(), g.jitter.value, g.jitter.stddev, g.jitter.verdict.c_str(),
                go.ref.segments, go.ref.scans, go.ref.spread.stride, go.ref.scene.c_str());
  rep.notes.push_back(buf);
}

}  // namespace spinradar::diagnose::detail
