#!/usr/bin/env bash
# `spinradar odometry` on the real Oxford sample (3 scans) must reproduce the dataset's
# ground-truth motion between consecutive scans: translation within MAX_T_PCT % of the step
# and rotation within MAX_R_DEG degrees. Exit 77 (skip) when the sample is absent.
# Measured (0.0438 m bins): every estimator is 4-6 % short of the ground truth on pair 1 and
# 2-4 % on pair 2 (keyframe: 5.8 % and 2.9 %, yaw within 0.05 deg).
# A feature-free check (cross-correlating the same azimuth rows of consecutive scans) shows
# the same shortfall in the raw data (2.22 m vs 2.40 m ahead), while GPS agrees with the
# ground truth (9.35 vs 9.29 m/s): the gap is in the data's range scale / this decelerating
# snippet, not in our frames or estimators (0.0432 m bins make it worse; ~0.046 would close
# it). Hence 7 %, not 2 %.
# Usage: oxford_odometry.sh SPINRADAR_BIN SHARED_DIR OUT_DIR [extra odometry options...]
set -euo pipefail
bin="$1"; shared="$2"; out="$3"; shift 3
seq="$shared/realdata/oxford_2019-01-10-14-36-48"
if [[ ! -d "$seq/radar" ]]; then echo "SKIP: Oxford sample not found at $seq" >&2; exit 77; fi
: "${MAX_T_PCT:=7}" "${MAX_R_DEG:=0.15}"
mkdir -p "$out"
"$bin" odometry --input "$seq" --out "$out/oxford_poses.csv" --quiet "$@"
"$bin" eval --est "$out/oxford_poses.csv" --gt "$seq/gt/radar_odometry.csv" --json "$out/oxford_eval.json"
/usr/bin/env python3 - "$out/oxford_eval.json" "$MAX_T_PCT" "$MAX_R_DEG" <<'PY'
import json, math, sys
r = json.load(open(sys.argv[1]))[0]
max_t, max_r = float(sys.argv[2]), float(sys.argv[3])
frames = r["frames"]
if len(frames) != 2:
    sys.exit(f"FAIL: expected 2 consecutive-scan motions, got {len(frames)} "
             f"({r['dropped']} estimated poses outside the ground truth)")
bad = 0
for f in frames:
    r_deg = math.degrees(f["r_err_rad"])
    ok = f["t_err_pct"] <= max_t and r_deg <= max_r
    bad += not ok
    print(f"t={f['t']:.6f}: gt step {f['gt_step_m']:.4f} m / {math.degrees(f['gt_dyaw_rad']):+.4f} deg,"
          f" est {f['est_step_m']:.4f} m / {math.degrees(f['est_dyaw_rad']):+.4f} deg ->"
          f" error {f['t_err_m']:.4f} m ({f['t_err_pct']:.2f} %), {r_deg:.4f} deg {'ok' if ok else 'FAIL'}")
sys.exit(1 if bad else 0)
PY
