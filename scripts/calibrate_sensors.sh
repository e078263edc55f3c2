#!/usr/bin/env bash
# Regenerates the calibrated sensor files config/sensors/{oxford,mulran,boreas_rt,radiate}.json
# with the appearance stage of `spinradar diagnose` on the real samples, and prints the README /
# docs/diagnose.md before/after table (scripts/appearance_table.py).
# Usage: scripts/calibrate_sensors.sh OUT [REALDATA]   (REALDATA defaults to ../shared/realdata)
# Needs the built CLI (scripts/cli_path.sh); about 20 minutes on one core with one start of the range curves (several times that with the default 3, --appearance-curve-starts), most of it Boreas-RT
# (6848 bins). Each sample's report: OUT/<sample>/appearance/appearance.md.
# Env: APPEARANCE_SCENE (the reference world of every sample's fit, in place of its own: Oxford
# and MulRan city_heights, the city with building, car and tree heights,
# docs/diagnose_height_visibility.md, docs/mulran_heights_refit.md; Boreas-RT and RADIATE city;
# city_facades: the city with the far structure of real streets, docs/city_scene_far_structure.md).
# diagnose writes the scene into each file as its "reference_scene" key, which simulate /
# serve / realism / the evaluation matrix then render the file in; APPEARANCE_HOLD (clutter:
# hold the clutter field at the start model's, i.e. off from the defaults, and fit the sensor
# terms only; docs/diagnose_hold_clutter.md); RENDER_SEEDS (noise seeds of the before /
# after figures, --render-seeds: means with their range) and FIT_SEEDS (noise seeds of the
# range-curve fit's objective, --appearance-fit-seeds; docs/diagnose_render_seeds.md).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:?usage: scripts/calibrate_sensors.sh OUT [REALDATA]}"
data="${2:-$root/../shared/realdata}"
source "$root/scripts/cli_path.sh"
cli="$(spinradar_cli_path "$root")"
[ -n "$cli" ] || { echo "no built spinradar CLI under $root/build (scripts/build.sh)" >&2; exit 1; }
[ -d "$data" ] || { echo "$data: no real data samples (see /work/shared/realdata/README.md)" >&2; exit 1; }
mkdir -p "$out"
run() {  # name, scene, diagnose arguments...
  local name="$1" scene="${APPEARANCE_SCENE:-$2}"; shift 2
  echo "== $name ($scene)" >&2
  "$cli" diagnose "$@" --appearance-scene "$scene" ${APPEARANCE_HOLD:+--appearance-hold "$APPEARANCE_HOLD"} ${RENDER_SEEDS:+--render-seeds "$RENDER_SEEDS"} ${FIT_SEEDS:+--appearance-fit-seeds "$FIT_SEEDS"} --out "$out/$name" > "$out/$name.log" 2>&1 \
    || { echo "$name: diagnose failed, see $out/$name.log" >&2; exit 1; }
  local fitted="$out/$name/appearance/sensor_fitted.json"
  cp "$fitted" "$root/config/sensors/$name.json.tmp"
  mv "$root/config/sensors/$name.json.tmp" "$root/config/sensors/$name.json"
}
# Oxford's shipped file is the height round's H3 (docs/diagnose_height_visibility.md): the
# file before it, refitted in city_heights with the far slope released, 8 fit seeds. With the
# default model as start the fit lands elsewhere; OXFORD_START (a sensor file) reproduces H3
# from the file it started from (git show e6a8975:config/sensors/oxford.json; with FIT_SEEDS=8,
# RENDER_SEEDS=8 as H3 was run).
run oxford city_heights --recording "$data/oxford_2019-01-10-14-36-48/radar" \
  ${OXFORD_START:+--sensor "$OXFORD_START" --appearance-iterations 0 --appearance-curve-starts 1 --appearance-fit-far-slope}
# MulRan's shipped file (docs/mulran_heights_refit.md, R2): the file before it refitted in
# city_heights, far slope released, up to 40 steps of the range curves, 4 fit seeds. MULRAN_START
# (git show d5b5928:config/sensors/mulran.json) reproduces it from that file (with FIT_SEEDS=4,
# RENDER_SEEDS=8 as R2 was run); without it the fit starts from the defaults.
run mulran city_heights --recording "$data/mulran" --format mulran --range-resolution 0.0595238 \
  ${MULRAN_START:+--sensor "$MULRAN_START" --appearance-iterations 0 --appearance-curve-starts 1 --appearance-fit-far-slope --appearance-curve-iterations 40}
run boreas_rt city --recording "$data/boreas_rt" --format boreas --range-resolution 0.04381
run radiate city --recording "$data/radiate_fog_6_0/Navtech_Polar" --format auto --range-resolution 0.17361
python3 "$root/scripts/appearance_table.py" "$out"
