#!/usr/bin/env bash
# Regenerates the calibrated sensor files config/sensors/{oxford,mulran,boreas_rt,radiate}.json
# with the appearance stage of `spinradar diagnose` on the real samples, and prints the README /
# docs/diagnose.md before/after table (scripts/appearance_table.py).
# Usage: scripts/calibrate_sensors.sh OUT [REALDATA]   (REALDATA defaults to ../shared/realdata)
# Needs the built CLI (scripts/cli_path.sh); about 20 minutes on one core with one start of the range curves (several times that with the default 3, --appearance-curve-starts), most of it Boreas-RT
# (6848 bins). Each sample's report: OUT/<sample>/appearance/appearance.md.
# Env: APPEARANCE_SCENE (the reference world of the fit, default city; city_facades: the city
# with the far structure of real streets, docs/city_scene_far_structure.md); APPEARANCE_HOLD
# (clutter: hold the clutter field at the start model's, i.e. off from the defaults, and fit the
# sensor terms only; docs/diagnose_hold_clutter.md); RENDER_SEEDS (noise seeds of the before /
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
run() {  # name, diagnose arguments...
  local name="$1"; shift
  echo "== $name" >&2
  "$cli" diagnose "$@" --appearance-scene "${APPEARANCE_SCENE:-city}" ${APPEARANCE_HOLD:+--appearance-hold "$APPEARANCE_HOLD"} ${RENDER_SEEDS:+--render-seeds "$RENDER_SEEDS"} ${FIT_SEEDS:+--appearance-fit-seeds "$FIT_SEEDS"} --out "$out/$name" > "$out/$name.log" 2>&1 \
    || { echo "$name: diagnose failed, see $out/$name.log" >&2; exit 1; }
  local fitted="$out/$name/appearance/sensor_fitted.json"
  cp "$fitted" "$root/config/sensors/$name.json.tmp"
  mv "$root/config/sensors/$name.json.tmp" "$root/config/sensors/$name.json"
}
run oxford --recording "$data/oxford_2019-01-10-14-36-48/radar"
run mulran --recording "$data/mulran" --format mulran --range-resolution 0.0595238
run boreas_rt --recording "$data/boreas_rt" --format boreas --range-resolution 0.04381
run radiate --recording "$data/radiate_fog_6_0/Navtech_Polar" --format auto --range-resolution 0.17361
python3 "$root/scripts/appearance_table.py" "$out"
