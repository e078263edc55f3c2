#pragma once
// Facade detail and street furniture of the "city_facades" scene (docs/city_scene_far_structure.md):
// point-like strong scatterers on and just in front of the city's building walls, and along the
// kerbs, that stay bright at grazing incidence (a smooth wall returns cos^n of it) and hence far
// down a street, as window frames, doors, drainpipes, balconies, signs and railings do on a real
// street. Added on top of the "city" world with its own random stream: the rest of the scene is
// the same scatterer for scatterer, and "city" itself is untouched.
#include <cstdint>
#include <vector>

#include "spinradar/sim/scene.hpp"

namespace spinradar::sim::detail {

/// Every number of the facade detail, in one place (documented in
/// docs/city_scene_far_structure.md, where the strengths are argued).
struct FacadeDetail {
  double min_wall_m = 6.0;         ///< walls shorter than this are cars, not buildings
  int floors_min = 2;              ///< storeys per building, uniform: the sensor's vertical fan
  int floors_max = 5;              ///<   sees every storey beyond ~20 m, so the details of a bay
                                   ///<   stacked over F storeys add up: + 10 log10(F) dB
  double bay_min_m = 2.5;          ///< spacing of window / door bays along a facade: uniform
  double bay_max_m = 4.5;
  double opening_min_m = 0.9;      ///< width of an opening; each of its two reveals (frame
  double opening_max_m = 1.6;      ///<   corners, sills) is one detail
  double depth_min_m = 0.1;        ///< in front of the wall plane (frames, sills, drainpipes)
  double depth_max_m = 0.5;
  double rcs_mean_db = 0.0;        ///< dBsm per detail and storey: normal(mean, sd), clamped
  double rcs_sd_db = 5.0;          ///<   to [lo, hi]
  double rcs_lo_db = -12.0;
  double rcs_hi_db = 12.0;
  double balcony_share = 0.15;     ///< share of bays with balconies / railings: one more detail
  double balcony_depth_m = 1.2;    ///<   further out and stronger (metal rails)
  double balcony_extra_db = 4.0;
  double pipe_min_m = 8.0;         ///< drainpipes: spacing uniform in [min, max], 0.15 m out
  double pipe_max_m = 16.0;
  double pipe_rcs_db = 3.0;        ///< dBsm per storey (a metal cylinder, ~0.1 m)
  double rough_min_m = 0.3;        ///< facade roughness (brick, stone, render, ledges, sills of
  double rough_max_m = 0.7;        ///<   the storeys above): weak scatterers along every wall,
  double rough_depth_m = 0.3;      ///<   spacing uniform in [min, max], 0..depth out; diffuse,
  double rough_rcs_mean_db = -12.0;  ///< so the same at any incidence: dBsm per scatterer and
  double rough_rcs_sd_db = 5.0;      ///<   storey, normal(mean, sd)
  double corner_rcs_min_db = 5.0;  ///< each building corner (quoins, drainpipes): uniform
  double corner_rcs_max_db = 15.0;
  double furniture_min_m = 8.0;    ///< street furniture along each kerb (signs, bollards, bins,
  double furniture_max_m = 20.0;   ///<   bike racks, railings): spacing uniform in [min, max]
  double furniture_off_min_m = 5.2;  ///< from the street's centre line (kerb 4.5-7 m)
  double furniture_off_max_m = 6.4;
  double furniture_rcs_min_db = -5.0;  ///< dBsm, uniform
  double furniture_rcs_max_db = 12.0;
  double junction_clear_m = 9.0;   ///< no furniture this close to a crossing's centre line
  // Heights (only when asked for, "city_heights"; docs/diagnose_height_visibility.md):
  double storey_m = 3.0;           ///< building height = floors * storey_m + roof_m (the same
  double roof_m = 1.0;             ///<   floors as the detail's stacking): 7-16 m
  double furniture_height_m = 2.5; ///< signs, posts, bus shelters: above a parked car's roof
};

/// Adds the facade detail to `w` (the city world of `grid` x `grid` blocks of `pitch` m): details
/// and roughness in front of every building wall (walls of at least min_wall_m; the city's boxes are drawn
/// counter-clockwise, so the outward normal of wall (x1,y1)->(x2,y2) is (dy, -dx)), a scatterer
/// at each building corner, and street furniture along every street, junctions kept clear.
/// Deterministic in `variant`. With `building_heights`, every wall of a building gets its
/// height (floors * storey_m + roof_m; other walls left unset, their entry 0), written there by
/// wall index, and every added target a height: the facade detail its building's top (it stands
/// for the detail of all its storeys), the furniture furniture_height_m. The draws are the same.
void addFacadeDetail(World& w, uint64_t variant, int grid, double pitch,
                     const FacadeDetail& p = FacadeDetail{},
                     std::vector<double>* building_heights = nullptr);

}  // namespace spinradar::sim::detail
