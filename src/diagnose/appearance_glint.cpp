// Appearance stage: the glint finding (glint_fit.hpp) added to the catalogue's findings.
#include <cstdio>

#include "appearance_detail.hpp"
#include "spinradar/diagnose/glint_fit.hpp"

namespace spinradar::diagnose::detail {

void appendGlint(const std::vector<PolarScan>& real, const sim::SensorConfig& cur,
                 sim::PhysicsConfig& phys, const AppearanceOptions& opt, AppearanceReport& rep) {
  GlintOptions go;
  go.seed = opt.seed;
  go.z_min = opt.z_min;
  const GlintFit g = fitGlint(real, cur, phys, go);
  AppearanceFinding f = makeFinding("scatterer glint", "glint", "m", g.base, g.value, g.stddev,
                                    std::abs(g.value - g.base), "m", g.named, opt.z_min);
  f.z = g.z, f.named = g.named, f.verdict = g.verdict;
  if (!g.measured) {
    rep.notes.push_back("Glint not identifiable: the recording has no two distinct consecutive scans.");
    rep.findings.push_back(f);
    return;
  }
  f.gap_before = g.real.all.tangential - g.before.all.tangential;
  f.gap_after = g.real.all.tangential - g.after.all.tangential;
  if (g.named) phys.extra["glint"] = g.value;
  char buf[400];
  std::snprintf(buf, sizeof buf,
                "Glint: returns matched between consecutive scans spread %.3f m across the beam "
                "(%.3f along; %d pairs), the model %.3f (%.3f) with glint %.3f m and %.3f (%.3f) "
                "with %.3f +- %.3f m (%s); reference: %d x %d consecutive scans of the city route.",
                g.real.all.tangential, g.real.all.radial, g.real.pairs, g.before.all.tangential,
                g.before.all.radial, g.base, g.after.all.tangential, g.after.all.radial, g.value,
                g.stddev, g.verdict.c_str(), go.segments, go.scans);
  rep.notes.push_back(buf);
  rep.findings.push_back(f);
}

}  // namespace spinradar::diagnose::detail
