#!/usr/bin/env bash
# `odometry` reads a recording at the range bin size its sensor.json states (a RADIATE-model
# recording has 0.174 m bins, not the Oxford layout's 0.0438 m): the travelled distance matches
# the truth; --range-resolution still overrides it; a recording's ranges get no dataset range
# offset (a MulRan-model recording has 3360 bins, the Boreas layout, whose -0.31 m offset it
# must not get); a malformed sensor.json is a named error.
# Usage: odometry_recorded_sensor.sh SPINRADAR_BIN OUT_DIR
set -euo pipefail
bin="$1"; out="$2"
rm -rf "$out"; mkdir -p "$out"
"$bin" simulate --scene city --sensor radiate --t0 20 --scans 6 --out "$out/drive" 2>"$out/simulate.log"
"$bin" odometry --input "$out/drive/radar" --quiet --out "$out/own.csv" 2>"$out/own.log"
grep -q "range bins of 0.17361 m from .*drive/sensor.json" "$out/own.log" \
  || { echo "FAIL: sensor.json not read"; cat "$out/own.log"; exit 1; }
grep -q "ranges as recorded (no dataset range offset)" "$out/own.log" \
  || { echo "FAIL: range offset not stated"; cat "$out/own.log"; exit 1; }
"$bin" simulate --scene city --sensor mulran --t0 20 --scans 4 --out "$out/mulran" 2>"$out/simulate_mulran.log"
"$bin" odometry --input "$out/mulran" --quiet --out "$out/mulran.csv" 2>"$out/mulran.log"
grep -q "boreas scans" "$out/mulran.log" || { echo "FAIL: 3360 bins not read as the Boreas layout"; cat "$out/mulran.log"; exit 1; }
grep -q "ranges as recorded (no dataset range offset)" "$out/mulran.log" \
  || { echo "FAIL: the Boreas range offset was applied to a recording"; cat "$out/mulran.log"; exit 1; }
# Same poses as when read as the Oxford layout (exact ranges, no offset) at the same bin size.
"$bin" odometry --input "$out/mulran" --quiet --format oxford --range-resolution 0.0595238 \
  --out "$out/mulran_oxford.csv" 2>"$out/mulran_oxford.log"
cmp -s "$out/mulran.csv" "$out/mulran_oxford.csv" \
  || { echo "FAIL: the recording's ranges differ from the exact ones"; diff "$out/mulran.csv" "$out/mulran_oxford.csv" | head; exit 1; }
"$bin" odometry --input "$out/drive" --quiet --range-resolution 0.0438 --out "$out/forced.csv" 2>"$out/forced.log"
/usr/bin/env python3 - "$out/drive/trajectory.csv" "$out/own.csv" "$out/forced.csv" <<'PY'
import csv, math, sys
truth = [(float(r["t"]), float(r["x"]), float(r["y"])) for r in csv.DictReader(open(sys.argv[1]))]
def travelled(path):
    rows = list(csv.DictReader(open(path)))
    return float(rows[-1]["t"]), math.hypot(float(rows[-1]["x"]), float(rows[-1]["y"]))
t_end, own = travelled(sys.argv[2])
_, forced = travelled(sys.argv[3])
t0 = float(list(csv.DictReader(open(sys.argv[2])))[0]["t"])
def at(t):
    return min(truth, key=lambda r: abs(r[0] - t))
a, b = at(t0), at(t_end)
true = math.hypot(b[1] - a[1], b[2] - a[2])
print(f"travelled: truth {true:.3f} m, own bins {own:.3f} m, forced 0.0438 m bins {forced:.3f} m")
if true < 1.0: sys.exit("FAIL: the drive did not move")
# Within 20 % (six scans from standstill); a wrong bin size is off by a factor of four.
if abs(own - true) > 0.2 * true: sys.exit("FAIL: not read at the recording's bin size")
# Within 15 %: the two runs see the scene at different scales and drift differently (7.6 % apart
# with the 2026-11 RADIATE calibration); not overriding would give a ratio of 1, four times this.
if abs(forced / own - 0.0438 / 0.17361) > 0.15 * 0.0438 / 0.17361:
    sys.exit("FAIL: --range-resolution did not override sensor.json")
PY
echo '{"range_resolution": "wide"}' > "$out/drive/sensor.json"
if "$bin" odometry --input "$out/drive" --quiet --out "$out/bad.csv" 2>"$out/bad.log"; then
  echo "FAIL: a malformed sensor.json was accepted"; exit 1
fi
grep -q "error: .*drive/sensor.json" "$out/bad.log" || { echo "FAIL: error does not name sensor.json"; cat "$out/bad.log"; exit 1; }
[ ! -e "$out/bad.csv" ] || { echo "FAIL: output written despite the error"; exit 1; }
echo "OK"
