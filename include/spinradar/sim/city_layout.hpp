#pragma once
// Street geometry of the city scenes: "city" / "city_facades" (14 m streets, buildings close to
// the kerb) and "city_open" (wider streets, buildings set back further, wider gaps between them),
// the appearance reference for real urban routes whose near facades do not hide everything
// behind them (docs/diagnose_far_band.md, section 5). The defaults ARE the city: its layout's
// numbers in one place, so the city scenes render as they always did.
namespace spinradar::sim::detail {

struct CityLayout {
  int grid = 6;                  ///< blocks per side
  double pitch_m = 64.0;         ///< street centre line to centre line
  double half_street_m = 7.0;    ///< centre line to the block edge; kerb-side objects (parked
                                 ///<   cars, poles, verges, trees, furniture) keep their distance
                                 ///<   to it, so they move out by half_street_m - 7
  double setback_max_m = 2.5;    ///< each building wall set back uniform [0, max] from the edge
  double gap_min_m = 2.0;        ///< gap between the buildings of a block, uniform [min, max]
  double gap_max_m = 5.0;        ///<   (at most half a building's share of the block)
};

/// The "city_open" layout: 20 m streets, buildings set back up to 6 m, 4-12 m gaps. Chosen (of
/// 12 layouts, docs/diagnose_far_band.md 5.1) because its first strong return along a row
/// matches the real Oxford route's (median 13.7 m against 13.8 m; city 8.1 m).
inline CityLayout openCityLayout() {
  CityLayout l;
  l.half_street_m = 10.0;
  l.setback_max_m = 6.0;
  l.gap_min_m = 4.0;
  l.gap_max_m = 12.0;
  return l;
}

}  // namespace spinradar::sim::detail
