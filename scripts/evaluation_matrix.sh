#!/usr/bin/env bash
# The evaluation matrix the default estimator is chosen from (issue 19): rows are estimators
# and front-end options, columns are data sets. One markdown table of KITTI drift
# (% / deg/m, 100..800 m subsequences) per simulated column and, for the real Oxford sample
# (../shared/realdata, 2 consecutive-scan pairs with the dataset's ground truth; and its scans
# 1 and 3 as one pair, oxford_real_skip), the mean per-pair yaw error (deg) / translation
# error (%). Held-out columns (not looked at while tuning) are printed in a second table.
# Simulated recordings carry sensor.json, so odometry reads them at their own bin size and
# without a dataset range offset (3360 / 6848 bins would otherwise get Boreas' -0.31 m).
#
# Simulated columns: the built-in scenes with full physics (motion distortion, Doppler
# beta 0.049 s, moving cars) under several sensor models (--sensor JSON subsets of
# include/spinradar/sim/sensor_config.hpp): range PSF wide (today's 2.7 bins sigma in power)
# and narrow (0.64 bins: 1.5 bins FWHM), beam width 1.5 / 2.4 deg (default 1.8), a higher
# noise floor, 4x the ground-clutter density (the world file's weak clutter scatterers
# replicated with jitter, then simulated with --world), plus every calibrated sensor model
# in config/sensors/*.json when there is one.
#
# Usage: scripts/evaluation_matrix.sh [OUT_DIR]      (default build/evaluation_matrix)
# Env: SPINRADAR_BIN (CLI), SCANS (scans per simulated column, default 480 = 2 min),
#      THREADS (default 2), COLS / ROWS (space-separated labels to restrict to),
#      SEEDS (noise seeds of every simulated column, default "1 2 3": one cell is one noise draw,
#      and draws of one column differ up to 2x, so a cell is the mean over the seeds, printed with
#      the seeds' range; SEED=n alone is SEEDS=n),
#      STEP (devkit first-frame step, default 4), SHARED (default ../shared next to the repo),
#      MERGE (further results.tsv files, e.g. of a run on other COLS, to print in the tables),
#      TABLE_ONLY=1 (print the tables of OUT_DIR/results.tsv and MERGE, run nothing),
#      LAYOUT_COLS (columns also run on street layouts 1 and 2, default city_wide city_narrow
#      city_oxford city_mulran; "" for none),
#      CITY_SCENE (the built-in scene of every city_* column, default city; city_facades adds
#      the far structure of real streets, docs/city_scene_far_structure.md), except the
#      calibrated columns (city_<sensor>, city_oxford_glint0.14) of a file with a
#      "reference_scene" key, which render in that scene (Oxford, MulRan: city_heights).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/build/evaluation_matrix}"
scans="${SCANS:-480}"
threads="${THREADS:-2}"
seeds="${SEEDS:-${SEED:-1 2 3}}"
step="${STEP:-4}"
shared="${SHARED:-$root/../shared}"
city="${CITY_SCENE:-city}"
[[ -d "$shared/realdata" ]] || shared="/work/shared"

source "$root/scripts/cli_path.sh"
bin="$(spinradar_cli_path "$root")"
[[ -n "$bin" && -x "$bin" ]] || { echo "error: spinradar CLI not found (build first or set SPINRADAR_BIN)" >&2; exit 1; }
mkdir -p "$out"

# --- rows: label = odometry options -------------------------------------------------------
# Every row names its front end: azimuth_peaks is on by default since 2026-11-27, and the rows
# without "+peaks" are the paper's front end (one keypoint per row at the row angle). Every row
# pins keyframe_graph, so a row means the same whatever the default ("+graph": window 6,
# "+step": with keyframe_graph_step), and every keyframe row pins keyframe_distance (10 m unless
# the label says otherwise: the default before the twenty-second round).
declare -A row_args=(
  [rigid]="--estimator rigid --azimuth_peaks false"
  [mc]="--estimator mc --azimuth_peaks false"
  [mc_doppler]="--estimator mc_doppler --azimuth_peaks false"
  [refined]="--estimator refined --azimuth_peaks false"
  [keyframe]="--estimator keyframe --azimuth_peaks false --keyframe_graph 0 --submap_keyframes 1 --yaw_rate_map_check false --start_rate_pair_weight 0 --keyframe_distance 10"
  [keyframe+peaks]="--estimator keyframe --azimuth_peaks true --keyframe_graph 0 --submap_keyframes 1 --yaw_rate_map_check false --start_rate_pair_weight 0 --keyframe_distance 10"
  [keyframe+peaks+graph]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step false --submap_keyframes 1 --yaw_rate_map_check false --start_rate_pair_weight 0 --keyframe_distance 10"
  [keyframe+peaks+graph+step]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 1 --yaw_rate_map_check false --start_rate_pair_weight 0 --keyframe_distance 10"
  # The eighteenth round's candidate: the map averaged with the previous keyframe's where the
  # two agree (docs/sensor_columns/round18_submap_agreement.md).
  [keyframe+peaks+graph+step+submap2]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 2 --yaw_rate_map_check false --start_rate_pair_weight 0 --keyframe_distance 10"
  # The nineteenth round's default: with it a registration's repeated yaw-rate difference is
  # the map's error (docs/sensor_columns/round19_map_rate_bias.md).
  [keyframe+peaks+graph+step+submap2+mapcheck]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 2 --yaw_rate_map_check true --start_rate_pair_weight 0 --keyframe_distance 10"
  # The default since the twentieth round: the nineteenth's plus the turn-heading blend
  # (docs/sensor_columns/round20_start_rate_default.md).
  [keyframe+peaks+graph+step+submap2+mapcheck+start0.25]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 2 --yaw_rate_map_check true --start_rate_pair_weight 0.25 --keyframe_distance 10"
  # The default since the twenty-second round: keyframes 9 m apart instead of 10
  # (docs/sensor_columns/round22_keyframe_spacing_phases.md).
  [keyframe+peaks+graph+step+submap2+mapcheck+start0.25+distance9]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 2 --yaw_rate_map_check true --start_rate_pair_weight 0.25 --keyframe_distance 9"
  # The twentieth round's default with keyframes 7 m apart instead of 10
  # (docs/sensor_columns/round21_keyframe_spacing.md): better on the calibrated real-sensor
  # models, worse on the simulator's own.
  [default+distance7]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 2 --yaw_rate_map_check true --start_rate_pair_weight 0.25 --keyframe_distance 7"
  # The turn-heading option (docs/sensor_columns/round16_turn_heading.md) on the sixteenth round's default row.
  [default+start_rate0.25]="--estimator keyframe --azimuth_peaks true --keyframe_graph 6 --keyframe_graph_step true --submap_keyframes 1 --yaw_rate_map_check false --start_rate_pair_weight 0.25 --keyframe_distance 10"
  [surface]="--estimator surface --azimuth_peaks false --keyframe_graph 0"
  [surface+peaks]="--estimator surface --azimuth_peaks true --keyframe_graph 0"
)
default_row="keyframe+peaks+graph+step+submap2+mapcheck+start0.25+distance9"  # the row the CLI's defaults give (issue 19)
all_rows=(rigid mc mc_doppler refined keyframe keyframe+peaks keyframe+peaks+graph keyframe+peaks+graph+step keyframe+peaks+graph+step+submap2 keyframe+peaks+graph+step+submap2+mapcheck keyframe+peaks+graph+step+submap2+mapcheck+start0.25 keyframe+peaks+graph+step+submap2+mapcheck+start0.25+distance9 default+distance7 default+start_rate0.25 surface surface+peaks)
# Rows whose estimator this CLI does not know are left out (older builds).
rows=()
# Read once: `grep -q` closing the pipe early made `params` die of SIGPIPE, and with pipefail a
# known estimator looked unknown (its row skipped).
estimators="$("$bin" params 2>/dev/null | grep "^| *estimator |" || true)"
for r in ${ROWS:-${all_rows[@]}}; do
  [[ -n "${row_args[$r]:-}" ]] || { echo "error: unknown row '$r' (rows: ${all_rows[*]})" >&2; exit 1; }
  est="$(sed -n 's/.*--estimator \([a-z_]*\).*/\1/p' <<< "${row_args[$r]}")"
  if [[ -n "$estimators" && "$estimators" != *"$est"* ]]; then
    echo "note: row $r skipped (this build has no estimator '$est')" >&2; continue
  fi
  rows+=("$r")
done

# --- columns: label | scene | variant | sensor JSON | clutter factor | held out ------------
cols_spec=(
  "city_wide|$city|0|{}|1|no"
  "city_narrow|$city|0|{\"range_psf_sigma_bins\": 0.64}|1|no"
  "city_beam1.5|$city|0|{\"beam_width_deg\": 1.5}|1|no"
  "city_beam2.4|$city|0|{\"beam_width_deg\": 2.4}|1|no"
  "city_noise14|$city|0|{\"noise_floor_db\": 14.0}|1|no"
  "city_clutter4x|$city|0|{}|4|no"
  "tight_turns|tight_turns|0|{}|1|no"
  "out_and_back_v2|out_and_back|2|{}|1|no"
  "city_v5_narrow_beam2.4|$city|5|{\"range_psf_sigma_bins\": 0.64, \"beam_width_deg\": 2.4}|1|yes"
  "out_and_back|out_and_back|0|{}|1|yes"
  # Glint (physics "glint", m: each scan moves every scattering centre by that much per axis):
  # real returns matched between scans spread 0.15-0.25 m across the beam, the simulator's
  # without glint 0.05-0.07 m (docs/diagnose_glint.md; fitted Oxford 0.09-0.14, RADIATE 0.18).
  "city_glint0.14|$city|0|{}|1|no|\"glint\": 0.14"
  # The calibrated files carry the glint terms fitted on the real samples (physics block of
  # config/sensors, eighth round): city_oxford and city_radiate have them; this column keeps
  # the seventh round's isotropic 0.14 m instead, with the file's terms set to 0.
  "city_oxford_glint0.14|$city|0|@oxford|1|no|\"glint\": 0.14, \"glint_across\": 0, \"glint_along\": 0, \"azimuth_jitter\": 0"
  "out_and_back_glint0.18|out_and_back|0|{}|1|yes|\"glint\": 0.18"
)
# A calibrated file is rendered in the scene it was calibrated in, its "reference_scene" key
# (include/spinradar/sim/reference_scene.hpp: Oxford's fit takes the 16 m returns 8 dB down
# because the facades behind the parked cars show in city_heights; in city they do not).
# CITY_SCENE applies to the files without the key and to the non-calibrated city columns.
sensor_scene() {  # sensor JSON file -> its reference_scene, else $city
  /usr/bin/env python3 - "$1" "$city" <<'PY'
import json, re, sys
path, fallback = sys.argv[1], sys.argv[2]
try:
    with open(path) as f:
        j = json.load(f)
except (OSError, ValueError) as e:
    sys.exit(f"error: {path}: cannot read the sensor file ({e})")
if not isinstance(j, dict):
    sys.exit(f"error: {path}: not a JSON object")
s = j.get("reference_scene", fallback)
if not isinstance(s, str) or not re.fullmatch(r"[a-z][a-z0-9_]*", s):
    sys.exit(f"error: {path}: reference_scene: {s!r} is not a scene name")
print(s)
PY
}
# "@name": the calibrated model config/sensors/name.json, in its reference scene.
for i in "${!cols_spec[@]}"; do
  IFS='|' read -r label scene variant sensor clutter held extra <<< "${cols_spec[$i]}"
  if [[ "$sensor" == @* ]]; then
    f="$root/config/sensors/${sensor#@}.json"
    [[ -f "$f" ]] || { echo "error: $f not found (column $label)" >&2; exit 1; }
    [[ "$scene" == "$city" ]] && scene="$(sensor_scene "$f")"
    cols_spec[$i]="$label|$scene|$variant|$(tr -d '\n' < "$f")|$clutter|$held${extra:+|$extra}"
  fi
done
for f in "$root"/config/sensors/*.json; do
  [[ -f "$f" ]] || continue
  cols_spec+=("city_$(basename "$f" .json)|$(sensor_scene "$f")|0|$(tr -d '\n' < "$f")|1|no")
done
# Layouts: some sensor columns again on two other street layouts of their scene (--variant 1, 2),
# as <label>_v1 / _v2, printed in a table of their own (LAYOUT_COLS="" leaves them out).
for base in ${LAYOUT_COLS-city_wide city_narrow city_oxford city_mulran}; do
  for spec in "${cols_spec[@]}"; do
    [[ "${spec%%|*}" == "$base" ]] || continue
    IFS='|' read -r _ scene _ sensor clutter _ extra <<< "$spec"
    for v in 1 2; do cols_spec+=("${base}_v$v|$scene|$v|$sensor|$clutter|layout|$extra"); done
  done
done
cols_spec+=("oxford_real|-|-|-|-|no")
# The same 3 real scans as one pair with twice the baseline (scan 1 -> 3, 0.5 s): a third
# real measurement, nearly independent of the two consecutive pairs' (the truth is the
# dataset's own chain, interpolated at the two scans' stamps by `eval`).
cols_spec+=("oxford_real_skip|-|skip|-|-|no")
# Real scans without ground truth (RADIATE fog_6_0, 18 scans): self-consistency. Each scan
# pair two apart (i -> i+2) is estimated directly (every other scan, both parities: 16 pairs)
# and as the chain of the full run; the rms of the yaw difference (deg) / of the step length
# difference (m) bounds the estimator's real-scan noise from below (errors common to both
# runs, a bias, cancel). Lower is better.
cols_spec+=("radiate_real_consistency|radiate|-|-|-|no")

cat > "$out/physics_full.json" <<'EOF'
{"motion_distortion": true, "doppler": 0.049, "moving_objects": true}
EOF

# 4x clutter: every weak static point scatterer (rcs < -28 dBsm: the scene's ground clutter;
# trees are -30..-18) gets factor-1 jittered copies with fresh reflectivities.
multiply_clutter() {  # world_in world_out factor seed
  /usr/bin/env python3 - "$@" <<'PY'
import json, random, sys
src, dst, factor, seed = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
w = json.load(open(src))
rng = random.Random(seed)
extra = []
for t in w["targets"]:
    if t.get("rcs", 10) < -28 and not t.get("vx") and not t.get("vy"):
        for _ in range(factor - 1):
            extra.append({"x": t["x"] + rng.uniform(-2, 2), "y": t["y"] + rng.uniform(-2, 2),
                          "rcs": -40.0 + 7.0 * rng.gauss(0, 1)})
w["targets"] += extra
json.dump(w, open(dst + ".tmp", "w"))
import os; os.replace(dst + ".tmp", dst)
print(f"clutter x{factor}: {len(extra)} scatterers added", file=sys.stderr)
PY
}

simulate_column() {  # label seed scene variant sensor clutter [extra physics, JSON members]
  local label="$1" seed="$2" scene="$3" variant="$4" sensor="$5" clutter="$6" extra="${7:-}"
  local rec="$out/rec_${label}_s$seed" physics="$out/physics_full.json"
  if [[ -n "$extra" ]]; then
    physics="$out/physics_$label.json"
    sed "s/}\s*$/, $extra}/" "$out/physics_full.json" > "$physics"
  fi
  local stamp="scene=$scene variant=$variant seed=$seed scans=$scans clutter=$clutter sensor=$sensor physics=$(tr -d ' \n' < "$physics")"
  if [[ -f "$rec/.spinradar_matrix" && "$(cat "$rec/.spinradar_matrix")" == "$stamp" ]]; then return; fi
  rm -rf "$rec"
  echo "$sensor" > "$out/sensor_$label.json"
  local args=(simulate --physics "$physics" --sensor "$out/sensor_$label.json"
              --seed "$seed" --scans "$scans" --out "$rec")
  if [[ "$clutter" != 1 ]]; then
    # The built-in scene's world and route, written once, then the clutter multiplied.
    local base="$out/base_${scene}_$variant"
    if [[ ! -f "$base/world.json" ]]; then
      "$bin" simulate --scene "$scene" --variant "$variant" --scans 1 --out "$base" 2> /dev/null
    fi
    multiply_clutter "$base/world.json" "$out/world_$label.json" "$clutter" "$((variant + 11))"
    args+=(--world "$out/world_$label.json" --trajectory "$base/trajectory.csv")
  else
    args+=(--scene "$scene" --variant "$variant")
  fi
  echo "== simulating $label, seed $seed ($scans scans)" >&2
  "$bin" "${args[@]}" 2> "$out/simulate_${label}_s$seed.log"
  echo "$stamp" > "$rec/.spinradar_matrix"
}

results="$out/results.tsv"
# TABLE_ONLY=1: print the tables of an earlier run (and MERGE) without running anything.
[[ -n "${TABLE_ONLY:-}" ]] && cols_spec=()
[[ -n "${TABLE_ONLY:-}" ]] || : > "$results"
for spec in "${cols_spec[@]}"; do
  IFS='|' read -r label scene variant sensor clutter held extra <<< "$spec"
  if [[ -n "${COLS:-}" && " $COLS " != *" $label "* ]]; then continue; fi
  if [[ "$scene" == "radiate" ]]; then
    seq="$shared/realdata/radiate_fog_6_0"
    [[ -f "$seq/Navtech_Polar.txt" ]] || { echo "note: $seq absent, RADIATE column skipped" >&2; continue; }
    for par in 0 1; do  # every other scan, by parity, as its own RADIATE folder (links)
      d="$out/radiate_skip$par"
      rm -rf "$d"; mkdir -p "$d/Navtech_Polar"
      awk -v p=$par 'NR % 2 == p' "$seq/Navtech_Polar.txt" > "$d/Navtech_Polar.txt"
      while read -r _ frame _ _; do
        ln -s "$seq/Navtech_Polar/$frame.png" "$d/Navtech_Polar/$frame.png"
      done < "$d/Navtech_Polar.txt"
    done
    for r in "${rows[@]}"; do
      e="$out/${label}__$r"
      echo "== $label: $r" >&2
      for in_out in "$seq|$e" "$out/radiate_skip0|${e}_skip0" "$out/radiate_skip1|${e}_skip1"; do
        # shellcheck disable=SC2086
        "$bin" odometry --input "${in_out%%|*}" --out "${in_out#*|}.csv" --quiet --threads "$threads" ${row_args[$r]} 2>> "$e.log"
      done
      /usr/bin/env python3 - "$e.csv" "${e}_skip0.csv" "${e}_skip1.csv" "$e.json" <<'PY'
import csv, json, math, os, sys
def load(p):
    return {round(float(r["t"]), 4): (float(r["x"]), float(r["y"]), float(r["yaw"]))
            for r in csv.DictReader(open(p))}
wrap = lambda a: math.atan2(math.sin(a), math.cos(a))
full, dy, dl = load(sys.argv[1]), [], []
for path in sys.argv[2:4]:
    s = load(path)
    st = sorted(s)
    for a, b in zip(st, st[1:]):
        if a in full and b in full:
            dy.append(math.degrees(wrap(wrap(full[b][2] - full[a][2]) - wrap(s[b][2] - s[a][2]))))
            dl.append(math.hypot(full[b][0] - full[a][0], full[b][1] - full[a][1]) -
                      math.hypot(s[b][0] - s[a][0], s[b][1] - s[a][1]))
rms = lambda v: math.sqrt(sum(x * x for x in v) / len(v)) if v else float("nan")
out = [{"consistency": {"yaw_rms_deg": rms(dy), "length_rms_m": rms(dl), "pairs": len(dy),
                         "yaw_diffs_deg": dy}}]  # per pair: the table's bootstrap interval
json.dump(out, open(sys.argv[4] + ".tmp", "w"))
os.replace(sys.argv[4] + ".tmp", sys.argv[4])
PY
      printf '%s\t%s\t%s\t%s\t-\n' "$label" "$r" "$held" "$e.json" >> "$results"
    done
    continue
  fi
  if [[ "$scene" == "-" ]]; then
    seq="$shared/realdata/oxford_2019-01-10-14-36-48"
    [[ -d "$seq/radar" ]] || { echo "note: $seq absent, Oxford column skipped" >&2; continue; }
    input="$seq"
    if [[ "$variant" == "skip" ]]; then
      mapfile -t pngs < <(ls "$seq/radar" | sort)
      input="$out/oxford_skip/radar"
      rm -rf "$out/oxford_skip"; mkdir -p "$input"
      ln -s "$seq/radar/${pngs[0]}" "$seq/radar/${pngs[2]}" "$input/"
    fi
    for r in "${rows[@]}"; do
      e="$out/${label}__$r"
      # shellcheck disable=SC2086
      "$bin" odometry --input "$input" --format oxford --out "$e.csv" --quiet --threads "$threads" ${row_args[$r]} 2> "$e.log"
      "$bin" eval --est "$e.csv" --gt "$seq/gt/radar_odometry.csv" --json "$e.json" > /dev/null
      printf '%s\t%s\t%s\t%s\t-\n' "$label" "$r" "$held" "$e.json" >> "$results"
    done
    continue
  fi
  for seed in $seeds; do
    simulate_column "$label" "$seed" "$scene" "$variant" "$sensor" "$clutter" "$extra"
    rec="$out/rec_${label}_s$seed"
    # The recording's bin size (a calibrated sensor model may not have Oxford's 0.0438 m, which
    # odometry assumes for Oxford-layout PNGs: RADIATE's 0.174 m read as 0.0438 gave 60 % drift).
    res="$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1])).get("range_resolution", ""))' "$rec/sensor.json" 2> /dev/null || true)"
    res_args=()
    [[ -n "$res" ]] && res_args=(--range-resolution "$res")
    for r in "${rows[@]}"; do
      e="$out/${label}__${r}__s$seed"
      echo "== $label, seed $seed: $r" >&2
      # shellcheck disable=SC2086
      "$bin" odometry --input "$rec" --out "$e.csv" --quiet --threads "$threads" "${res_args[@]}" ${row_args[$r]} 2> "$e.log"
      "$bin" eval --est "$e.csv" --gt "$rec/trajectory.csv" --step "$step" --json "$e.json" > /dev/null
      printf '%s\t%s\t%s\t%s\t%s\n' "$label" "$r" "$held" "$e.json" "$seed" >> "$results"
    done
  done
done

# The default's losses with what resolves them (per seed, bootstrap over real pairs).
/usr/bin/env python3 "$root/scripts/evaluation_matrix_table.py" --default "$default_row" "$results" ${MERGE:-}
