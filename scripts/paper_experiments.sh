#!/usr/bin/env bash
# The paper's experiments (Burnett et al. 2021) on simulated drives, in one command:
#   Table I  - radar odometry with rigid RANSAC, MC-RANSAC and MC-RANSAC + Doppler over the
#              simulator's built-in city route with full physics (motion distortion, Doppler
#              beta = 0.049 s, moving objects), KITTI-style drift (100..800 m subsequences);
#              plus this package's keyframe estimator (issue 9) as an extra row.
#   Table II - metric localization against a drive in the opposite direction: provided by the
#              localization issue through `spinradar localize`; printed here once it exists.
# Usage: scripts/paper_experiments.sh [OUT_DIR]   (default build/paper_experiments)
# Env: SPINRADAR_BIN (CLI to use), SCENE (default city), VARIANT, SEED, SCANS (limit, for a
#      quick look), THREADS (default 2), STEP (devkit first-frame step, default 4 = 1 s at 4 Hz).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/build/paper_experiments}"
scene="${SCENE:-city}"
variant="${VARIANT:-0}"
seed="${SEED:-1}"
threads="${THREADS:-2}"
step="${STEP:-4}"

source "$root/scripts/cli_path.sh"
bin="$(spinradar_cli_path "$root")"
if [[ -z "$bin" ]]; then
  echo "== building spinradar (scripts/build.sh)" >&2
  bash "$root/scripts/build.sh"
  bin="$(spinradar_cli_path "$root")"
fi
[[ -x "$bin" ]] || { echo "error: spinradar CLI not found" >&2; exit 1; }
for sub in simulate odometry eval; do
  "$bin" "$sub" --help > /dev/null 2>&1 || { echo "error: '$bin' has no '$sub' subcommand" >&2; exit 1; }
done

mkdir -p "$out"
rec="$out/${scene}_full_physics"
cat > "$out/physics_full.json" <<'EOF'
{"motion_distortion": true, "doppler": 0.049, "moving_objects": true}
EOF

# --- simulate (skipped when the recording is already there with the same settings) ---
stamp="scene=$scene variant=$variant seed=$seed scans=${SCANS:-all} physics=$(tr -d ' \n' < "$out/physics_full.json")"
if [[ -f "$rec/.spinradar_paper" && "$(cat "$rec/.spinradar_paper")" == "$stamp" ]]; then
  echo "== reusing $rec" >&2
else
  rm -rf "$rec"
  echo "== simulating the $scene route with full physics -> $rec" >&2
  sim_args=(simulate --scene "$scene" --variant "$variant" --seed "$seed" --physics "$out/physics_full.json" --out "$rec")
  [[ -n "${SCANS:-}" ]] && sim_args+=(--scans "$SCANS")
  "$bin" "${sim_args[@]}"
  echo "$stamp" > "$rec/.spinradar_paper"
fi

# --- Table I: odometry with each estimator ---
labels=(rigid mc mc_doppler keyframe)
est_args=()
for est in "${labels[@]}"; do
  echo "== odometry, estimator $est" >&2
  "$bin" odometry --input "$rec" --out "$out/odometry_$est.csv" --estimator "$est" --threads "$threads" --quiet \
    2> >(tee "$out/odometry_$est.log" >&2)
  est_args+=(--est "$out/odometry_$est.csv" --label "$est")
done
echo "== evaluation" >&2
"$bin" eval "${est_args[@]}" --gt "$rec/trajectory.csv" --step "$step" \
  --plot "$out/odometry.png" --json "$out/odometry.json" > "$out/odometry_eval.txt"

/usr/bin/env python3 - "$out/odometry.json" "$scene" "$out" <<'PY'
import json, os, re, sys
rows = {r["label"]: r for r in json.load(open(sys.argv[1]))}
paper = {"rigid": (3.9777, 0.0141), "mc": (3.6042, 0.0119), "mc_doppler": (3.5847, 0.0118)}
names = {"rigid": "Rigid RANSAC", "mc": "MC-RANSAC", "mc_doppler": "MC-RANSAC + Doppler",
         "keyframe": "keyframe (this package, not in the paper)"}
r0 = rows["rigid"]
print()
print(f"Table I (simulated '{sys.argv[2]}' route, full physics: {r0['path_length_m']:.0f} m, "
      f"{r0['duration_s']:.0f} s, {r0['poses']} scans)")
print()
print("| Method | Translational Error (%) | Rotational Error (deg/m) | paper (Oxford): % | deg/m |")
print("|---|---|---|---|---|")
for k in ("rigid", "mc", "mc_doppler", "keyframe"):
    r = rows[k]
    if r["drift_valid"]:
        t, a = f"{r['t_err_pct']:.4f}", f"{r['r_err_deg_per_m']:.4f}"
    else:
        t, a = "n/a (< 100 m)", "n/a"
    pt, pa = (f"{paper[k][0]:.4f}", f"{paper[k][1]:.4f}") if k in paper else ("-", "-")
    print(f"| {names[k]} | {t} | {a} | {pt} | {pa} |")
def ms_per_scan(k):
    """Mean pipeline ms per scan from the odometry log (CPU time of the chain, not wall)."""
    try:
        for line in open(os.path.join(sys.argv[3], f"odometry_{k}.log")):
            m = re.match(r"\s*pipeline total\s+\S+ s\s+(\S+) ms", line)
            if m:
                return m.group(1)
    except OSError:
        pass
    return "?"
print()
print("ms per scan (detector to estimate): " + ", ".join(f"{k} {ms_per_scan(k)}" for k in names))
if all(rows[k]["drift_valid"] for k in paper):
    rt, mt, dt = (rows[k]["t_err_pct"] for k in ("rigid", "mc", "mc_doppler"))
    rr, mr, dr = (rows[k]["r_err_deg_per_m"] for k in ("rigid", "mc", "mc_doppler"))
    print()
    print(f"MC vs rigid: translational {100 * (rt - mt) / rt:+.1f} % reduction, rotational "
          f"{100 * (rr - mr) / rr:+.1f} % (paper: 9.4 %, 15.6 %)")
    print(f"Doppler on top of MC: translational {100 * (mt - dt) / mt:+.1f} %, rotational "
          f"{100 * (mr - dr) / mr:+.1f} % (paper: 0.5 %, 0.8 %: negligible)")
PY
echo
echo "(details: $out/odometry_eval.txt, plots: $out/odometry.png)"

# --- Table II: localization against a reverse drive (scripts/localization_experiment.sh) ---
echo
SPINRADAR_BIN="$bin" bash "$root/scripts/localization_experiment.sh" "$out/localization"
