#!/usr/bin/env bash
# Table II analogue (Burnett et al. 2021, "Metric Localization Results"): localize the return
# leg of the simulator's out_and_back scene against the outgoing leg, i.e. against a drive in
# the opposite direction, with full kinematic physics (motion distortion + Doppler beta 0.049 s).
# RSD descriptors, rigid RANSAC on keypoints with no compensation, motion compensation, and
# motion + Doppler compensation (each scan with its own MC-RANSAC velocity). The map scan of
# each live scan is the nearest by true pose (the paper pairs scans by GPS); statistics over
# live scans at >= MIN_SPEED m/s (the paper: > 10 m/s).
# Usage: scripts/localization_experiment.sh [OUT_DIR]   (default build/localization_experiment)
# Env: SPINRADAR_BIN (CLI to use), VARIANT, SEED, MIN_SPEED (default 10), PRIOR (truth|track).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/build/localization_experiment}"
variant="${VARIANT:-0}"
seed="${SEED:-1}"
min_speed="${MIN_SPEED:-10}"
prior="${PRIOR:-truth}"

source "$root/scripts/cli_path.sh"
bin="$(spinradar_cli_path "$root")"
[[ -x "$bin" ]] || { echo "error: spinradar CLI not found (build it, or set SPINRADAR_BIN)" >&2; exit 1; }
for sub in simulate localize; do
  "$bin" "$sub" --help > /dev/null 2>&1 || { echo "error: '$bin' has no '$sub' subcommand" >&2; exit 1; }
done

mkdir -p "$out"
rec="$out/out_and_back"
cat > "$out/physics.json" <<'EOF'
{"motion_distortion": true, "doppler": 0.049}
EOF
stamp="variant=$variant seed=$seed physics=$(tr -d ' \n' < "$out/physics.json")"
if [[ -f "$rec/.spinradar_loc" && "$(cat "$rec/.spinradar_loc")" == "$stamp" ]]; then
  echo "== reusing $rec" >&2
else
  rm -rf "$rec"
  echo "== simulating the out_and_back route -> $rec" >&2
  "$bin" simulate --scene out_and_back --variant "$variant" --seed "$seed" \
    --physics "$out/physics.json" --out "$rec"
  echo "$stamp" > "$rec/.spinradar_loc"
fi

# Split the route at the U-turn: map = poses before the heading leaves +x, live = scans after
# it settles on -x.
read -r t_turn t_back < <(awk -F, 'NR > 1 {
    c = cos($4)
    if (!a && c < 0.999) a = $1
    if (a && !b && c < -0.999) b = $1
  } END { print a, b }' "$rec/trajectory.csv")
[[ -n "$t_turn" && -n "$t_back" ]] || { echo "error: no U-turn found in $rec/trajectory.csv" >&2; exit 1; }
awk -F, -v t="$t_turn" 'NR == 1 || $1 < t' "$rec/trajectory.csv" > "$out/map_poses.csv"
echo "== map: scans before t = $t_turn s; live: scans from t = $t_back s" >&2

"$bin" localize --map "$rec" --map-poses "$out/map_poses.csv" --input "$rec" \
  --input-from "$t_back" --truth "$rec/trajectory.csv" --compensation all --prior "$prior" \
  --min-speed "$min_speed" --out "$out/localization.csv" --plot "$out/localization_errors.png" \
  | tee "$out/localization.txt"

/usr/bin/env python3 - "$out/localization.txt" "$min_speed" <<'PY'
import sys
rows = {}
for line in open(sys.argv[1]):
    p = line.split()
    if len(p) == 5 and p[0] in ("none", "motion", "motion_doppler"):
        rows[p[0]] = (int(p[1]), int(p[2]), float(p[3]), float(p[4]))
names = {"none": "No Compensation", "motion": "Motion-Compensated",
         "motion_doppler": "Motion-Compensated + Doppler-Compensated"}
paper = {"none": (2.2976, 0.7110), "motion": (1.3403, 1.0766), "motion_doppler": (0.4327, 0.9984)}
print()
print(f"Table II (simulated out_and_back, return leg against the outgoing leg, live scans at "
      f">= {sys.argv[2]} m/s)")
print()
print("| Method | Trans. Error (m) | Rot. Error (deg) | scans (failed) | paper: m | deg |")
print("|---|---|---|---|---|---|")
for k in ("none", "motion", "motion_doppler"):
    n, f, t, r = rows[k]
    print(f"| {names[k]} | {t:.4f} | {r:.4f} | {n} ({f}) | {paper[k][0]:.4f} | {paper[k][1]:.4f} |")
t0, t1, t2 = (rows[k][2] for k in ("none", "motion", "motion_doppler"))
print()
print(f"Motion compensation: {100 * (t0 - t1) / t0:.1f} % less translation error (paper 41.7 %); "
      f"Doppler on top: {100 * (t1 - t2) / t1:.1f} % (paper 67.7 %); "
      f"both: {100 * (t0 - t2) / t0:.1f} % (paper 81.2 %)")
PY
echo
echo "(per-scan poses and errors: $out/localization_<mode>.csv, histogram: $out/localization_errors.png)"
