#!/usr/bin/env bash
# `spinradar diagnose` reads a rosbag of RadarScan messages: a simulated drive with a hidden
# Doppler shift (beta 0.049 s), written to a bag by `spinradar simulate --bag`, must be diagnosed as `doppler` within 10 %.
# Usage: diagnose_bag.sh SPINRADAR_BIN OUT_DIR
set -euo pipefail
bin="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
echo '{"doppler": 0.049}' > "$out/hidden.json"
"$bin" simulate --scene tight_turns --physics "$out/hidden.json" --scans 8 --seed 5 --out "$out/rec" \
  --bag "$out/rec.bag" > /dev/null
"$bin" diagnose --recording "$out/rec.bag" --trajectory "$out/rec/trajectory.csv" \
  --world "$out/rec/world.json" --out "$out/diag"
/usr/bin/python3 - "$out/diag/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
assert r["mismatch_found"], "no mismatch reported"
e = r["effects"][0]
assert e["name"] == "doppler", "named %s, expected doppler" % e["name"]
assert abs(e["value"] - 0.049) < 0.0049, "beta %.4f not within 10 %% of 0.049" % e["value"]
print("ok: doppler beta %.4f +- %.4f from the bag" % (e["value"], e["stddev"]))
PY
