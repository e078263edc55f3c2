#pragma once
// Elevated structure of the "city_elevated" scene (docs/diagnose_elevated_structure.md): what a
// roof-mounted radar with a tall fan beam sees OVER the first row of buildings, which the 2-D
// depth map would hide: roof edges (gutters, coping, parapets), rooftop plant (chimneys, vents,
// antennas), the detail of the upper storeys that stand above the buildings in front, and tree
// crowns in the back gardens of the blocks. All are Target::elevated (not occluded by walls).
// Added on top of "city_facades" with its own random stream, appended: every earlier target
// keeps its place and value, and "city" / "city_facades" are untouched.
#include <cstdint>
#include <vector>

#include "spinradar/sim/scene.hpp"

namespace spinradar::sim::detail {

/// Every number of the elevated structure, in one place (strengths argued in
/// docs/diagnose_elevated_structure.md; dBsm per scatterer, as in city_facades.hpp).
struct ElevatedDetail {
  double min_wall_m = 6.0;          ///< boxes whose longest wall is shorter are cars
  double elevation_loss_db = 6.0;   ///< building-mounted items sit 8-20 m up: at 30-100 m that
                                    ///<   is 5-30 deg above the beam's axis (the fan's upper
                                    ///<   edge) and partly shadowed by the roofline in front
  int rise_max = 2;                 ///< storeys standing above the roofline in front, uniform
                                    ///<   0..max per building: 0 = a level roofline (roof edge
                                    ///<   and plant only); upper detail + 10 log10(rise) dB
  double roof_min_m = 1.0;          ///< roof edge (gutters, coping, flashing): spacing uniform
  double roof_max_m = 3.0;          ///<   [min, max] along every wall, 0..roof_depth out
  double roof_depth_m = 0.3;
  double roof_rcs_mean_db = -6.0;   ///< normal(mean, sd): a gutter run is a long thin metal
  double roof_rcs_sd_db = 5.0;      ///<   edge, bright only near broadside, so diffuse on average
  double bay_min_m = 2.5;           ///< upper-storey window bays, two reveals per opening, as
  double bay_max_m = 4.5;           ///<   the facade detail's (city_facades.hpp): normal(mean,
  double opening_min_m = 0.9;       ///<   sd) clamped to [lo, hi] per storey
  double opening_max_m = 1.6;
  double reveal_rcs_mean_db = 0.0;
  double reveal_rcs_sd_db = 5.0;
  double reveal_rcs_lo_db = -12.0;
  double reveal_rcs_hi_db = 12.0;
  double rough_min_m = 0.3;         ///< upper-storey roughness (brick, ledges, sills): spacing
  double rough_max_m = 0.7;         ///<   uniform, 0..rough_depth out; the facade roughness's
  double rough_depth_m = 0.3;       ///<   -12 dBsm per scatterer and storey
  double rough_rcs_mean_db = -12.0;
  double rough_rcs_sd_db = 5.0;
  int plant_max = 4;                ///< rooftop plant per building, uniform 0..max, anywhere on
  double plant_rcs_min_db = 0.0;    ///<   the roof 1 m in from its edge: chimney stacks, vents,
  double plant_rcs_max_db = 12.0;   ///<   HVAC boxes, antennas (metal and brick corners), uniform
  int crowns_max = 3;               ///< tree crowns per block (back gardens, courtyards), uniform
  double crown_min_m = 2.0;         ///<   0..max at any point of the block; radius uniform
  double crown_max_m = 4.0;         ///<   [min, max]
  int crown_points_min = 10;        ///< scatterers per crown, uniform [min, max], spread over
  int crown_points_max = 25;        ///<   the crown's disc
  double crown_rcs_mean_db = -15.0; ///< per scatterer, normal(mean, sd): a crown face of ~15 m^2
  double crown_rcs_sd_db = 5.0;     ///<   at sigma0 ~ -15 dB is ~ -3 dBsm, over ~16 scatterers
  // Heights in place of the flag ("city_heights", docs/diagnose_height_visibility.md):
  double upper_below_top_m = 1.5;   ///< upper-storey detail: the top storey's windows
  double plant_above_top_m = 1.5;   ///< rooftop plant stands this far above the roof
  double crown_height_per_radius = 3.0;  ///< crown top = 3 x radius: 6-12 m for 2-4 m crowns
};

/// Adds the elevated structure to `w` (the city world of `grid` x `grid` blocks of `pitch` m,
/// streets 2 `half_street` m wide): for every building box (four consecutive walls, the
/// city's boxes counter-clockwise, outward normal of (x1,y1)->(x2,y2) is (dy, -dx)) its roof
/// edge, rooftop plant and upper-storey detail; tree crowns in every block. Every added target
/// is elevated. Deterministic in `variant`. With `building_heights` (per wall index, from
/// addFacadeDetail) the added targets carry heights instead of the flag, and the renderer's
/// height rule decides what shows over what: roof edge at the building's top, upper-storey
/// detail upper_below_top_m below it, plant plant_above_top_m above it, crowns
/// crown_height_per_radius x radius. The draws are the same.
void addElevatedDetail(World& w, uint64_t variant, int grid, double pitch, double half_street,
                       const ElevatedDetail& p = ElevatedDetail{},
                       const std::vector<double>* building_heights = nullptr);

}  // namespace spinradar::sim::detail
