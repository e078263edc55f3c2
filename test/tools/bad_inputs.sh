#!/usr/bin/env bash
# Every bad input gives a named error and nothing is lost (issue 17): one row per bad input of
# every class (data loss, integer overflow, NaN, wrong format guesses, silent wrong results,
# unclear errors), built from the project's simulator and small files. Each failing row must
# exit 1..127 (no crash), print a message matching its pattern (the file and the reason), leave
# the output folder empty (no partial or temporary file) and leave every input unchanged
# (checksums of the whole input tree).
# Usage: bad_inputs.sh SPINRADAR_BIN OUT_DIR
set -uo pipefail
bin="$1"; out="$2"
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
png() { /usr/bin/python3 "$here/write_scan_png.py" "$@"; }
rm -rf "$out"; mkdir -p "$out/in" "$out/o"
in="$out/in"; o="$out/o"; err="$out/stderr.txt"
failures=0; rows=0

# ---- inputs -------------------------------------------------------------------------------
"$bin" simulate --scene city --scans 4 --out "$in/rec" > /dev/null 2>&1 || { echo "FAIL: simulate"; exit 1; }
"$bin" simulate --scene city --scans 4 --t0 1547131046 --out "$in/epoch" > /dev/null 2>&1 || { echo "FAIL: simulate epoch"; exit 1; }
first=$(ls "$in/rec/radar" | head -1)
mkdir -p "$in/names19/radar" "$in/names17/radar" "$in/stamp62/radar" "$in/narrow/radar" "$in/tall/radar" \
  "$in/rows10/radar" "$in/constenc/radar" "$in/zerostamps/radar" "$in/mulran_cut" "$in/mixed" "$in/dangling/radar" \
  "$in/real_empty" "$in/real_bad/mulran"
cp "$in/rec/radar/$first" "$in/names19/radar/9999999999999999999.png"
cp "$in/rec/radar/$first" "$in/names17/radar/99999999999999999.png"
png "$in/stamp62/radar/1000.png" 400 60 --stamp-us 4611686018427387904      # 2^62 us
png "$in/narrow/radar/1547131046353776.png" 400 12 --plain
png "$in/tall/radar/000001.png" 200000 400 --plain               # 400 wide, 200000 high
png "$in/rows10/radar/1547131046353776.png" 10 3779
png "$in/constenc/radar/1547131046353776.png" 400 60 --constant-encoder
for k in 1 2 3; do png "$in/zerostamps/radar/$k.png" 400 60 --zero-stamps; done
printf '1564718976161407002,0.0,9,1,12,40,3' > "$in/mulran_cut/1564718976161407002.csv"
cp "$in/rec/radar/$first" "$in/mixed/1547131046353776.png"; cp "$in/mulran_cut/"*.csv "$in/mixed/"
cp "$in/rec/radar/"*.png "$in/dangling/radar/"; ln -s "$in/nonexistent.png" "$in/dangling/radar/1.png"
echo "this is not a scan" > "$in/real_bad/mulran/1564718976161407002.csv"
awk -F, 'NR == 1 {print; next} {$1 = sprintf("%.9f", $1 + 1000); print}' OFS=, "$in/rec/trajectory.csv" > "$in/late_trajectory.csv"
echo '{"dopler": 0.049}' > "$in/misspelt_physics.json"
printf 'zq: 3\nzq: 4\n' > "$in/duplicate_keys.yaml"
printf 'zq: nan\n' > "$in/nan.yaml"
printf 'loc_nndr: nan\n' > "$in/loc_nan.yaml"
printf 't,x,y,yaw\n' > "$in/header_only.csv"
{ printf 'SPINCAP1'; head -c 92 /dev/zero; } > "$in/cap100.bin"
"$bin" odometry -q -i "$in/rec" -o "$in/est.csv" > /dev/null 2>&1 || { echo "FAIL: odometry"; exit 1; }
# A capture of 6 rotations from the simulator served on loopback, then the same cut short.
for attempt in 1 2 3; do
  port=$((20000 + RANDOM % 20000))
  "$bin" serve --scene city --port "$port" --rate 0 > /dev/null 2>&1 & spid=$!
  sleep 0.5
  timeout 60 "$bin" capture record --port "$port" --scans 6 --out "$in/cap.bin" > /dev/null 2>&1
  kill "$spid" 2> /dev/null; wait "$spid" 2> /dev/null
  [[ -s "$in/cap.bin" ]] && break
done
head -c $(( $(stat -c %s "$in/cap.bin") * 2 / 3 )) "$in/cap.bin" > "$in/cap_cut.bin"

checksum() { (cd "$in" && find . -type f -print0 | sort -z | xargs -0 md5sum && find . -type l -printf '%p -> %l\n' | sort) | md5sum; }

# fail_row NAME REGEX command...: must fail cleanly, name file and reason, lose nothing.
fail_row() {
  local name="$1" regex="$2"; shift 2
  rows=$((rows + 1))
  local before; before=$(checksum)
  "$@" > /dev/null 2> "$err"; local status=$?
  local why=""
  if [[ $status -eq 0 ]]; then why="succeeded, expected an error"
  elif [[ $status -ge 128 ]]; then why="crashed (status $status)"
  elif ! grep -Eq -- "$regex" "$err"; then why="message does not match /$regex/"
  elif grep -Eq '[0-9]{40}' "$err"; then why="message holds an unreadable number"
  elif [[ -n "$(ls -A "$o")" ]]; then why="left output behind: $(ls -A "$o" | tr '\n' ' ')"
  elif [[ "$(checksum)" != "$before" ]]; then why="changed an input"
  fi
  report "$name" "$why"
}

# warn_row NAME REGEX command...: succeeds, but names what it skipped or lost.
warn_row() {
  local name="$1" regex="$2"; shift 2
  rows=$((rows + 1))
  local before; before=$(checksum)
  "$@" > /dev/null 2> "$err"; local status=$?
  local why=""
  if [[ $status -ne 0 ]]; then why="failed with status $status"
  elif ! grep -Eq -- "$regex" "$err"; then why="warning does not match /$regex/"
  elif [[ "$(checksum)" != "$before" ]]; then why="changed an input"
  fi
  rm -rf "${o:?}"/* "$o"/.[!.]* 2> /dev/null
  report "$name" "$why"
}

report() {
  if [[ -n "$2" ]]; then
    failures=$((failures + 1)); echo "FAIL $1: $2"; sed 's/^/    /' "$err" | head -5
  else
    echo "ok   $1: $(grep -E 'error|warning|: ' "$err" | head -1 | cut -c1-160)"
  fi
}

# ---- 1. nothing lost --------------------------------------------------------------------------
fail_row "odometry -o onto an input scan" "$first: the output \(--out\) is the same file as --input" \
  "$bin" odometry -q -i "$in/rec" -o "$in/rec/radar/$first"
fail_row "odometry --tum onto its own --out" "same file as --out" \
  "$bin" odometry -q -i "$in/rec" -o "$o/a.csv" --tum "$o/a.csv"
fail_row "simulate into a non-empty folder" "rec: folder is not empty .*--force" \
  "$bin" simulate --scene city --scans 1 --out "$in/rec"
fail_row "simulate --out holding its --trajectory" "the output folder \(--out\) holds an input" \
  "$bin" simulate --world "$in/rec/world.json" --trajectory "$in/rec/trajectory.csv" --out "$in/rec" --force
fail_row "capture replay into a non-empty folder" "rec: folder is not empty" \
  "$bin" capture replay --in "$in/cap100.bin" --out "$in/rec"
fail_row "capture of 100 bytes" "cap100.bin: no complete rotation .*nothing written" \
  "$bin" capture replay --in "$in/cap100.bin" --out "$o/replayed"
warn_row "capture cut short" "cap_cut.bin: capture cut short at byte [0-9]+ .*the rotation in progress there is lost \(1 rotation; [0-9]+ complete" \
  "$bin" capture replay --in "$in/cap_cut.bin" --out "$o/replayed"
fail_row "failed run leaves no partial output" "nowhere/c.csv: cannot open for writing" \
  "$bin" odometry -q -i "$in/rec" -o "$o/poses.csv" --covariance-out "$o/nowhere/c.csv"
fail_row "eval --json onto its --gt" "same file as --gt" \
  "$bin" eval --est "$in/est.csv" --gt "$in/rec/trajectory.csv" --json "$in/rec/trajectory.csv"
if "$bin" bag --help 2>&1 | grep -q -- --force && ! "$bin" bag -i "$in/rec" -o "$o/x.bag" 2>&1 | grep -q "without ROS"; then
  rm -f "$o/x.bag"
  fail_row "bag onto an input scan" "same file as --input" \
    "$bin" bag -i "$in/rec" -o "$in/rec/radar/$first"
fi

# ---- 2. integer overflow ----------------------------------------------------------------------
fail_row "19-digit file name" "9999999999999999999.png: the number in the file name \(19 digits\) does not fit in 64 bits" \
  "$bin" odometry -q -i "$in/names19" -o "$o/p.csv"
fail_row "17-digit file name (us -> ns)" "99999999999999999.png: stamp in the file name \(us\).* does not fit in 64 bits" \
  "$bin" odometry -q -i "$in/names17" -o "$o/p.csv"
fail_row "stamps near 2^62 us" "1000.png: row 0: stamp 4611686018427387904 us is out of range" \
  "$bin" odometry -q -i "$in/stamp62" -o "$o/p.csv" --format oxford
fail_row "frame number x period (radiate on 17-digit names)" "frame number x rotation period .*does not fit" \
  "$bin" odometry -q -i "$in/names17" -o "$o/p.csv" --format radiate
fail_row "--format radiate on Oxford data" "3779 x 400 \(columns x rows\) but RADIATE images are 400 azimuths across.*--format oxford.*wrong --format" \
  "$bin" odometry -q -i "$in/rec" -o "$o/p.csv" --format radiate

# ---- 3. NaN, infinities, ranges, counts ------------------------------------------------------
fail_row "odometry --zq nan" "--zq.*'nan' is not a finite number" "$bin" odometry -i "$in/rec" -o "$o/p.csv" --zq nan
fail_row "YAML zq: nan" "nan.yaml:1: parameter 'zq': 'nan' is not a finite number" \
  "$bin" odometry -i "$in/rec" -o "$o/p.csv" --config "$in/nan.yaml"
fail_row "eval --gt-sensor-pose nan" "--gt-sensor-pose.*not a finite number" \
  "$bin" eval --est "$in/est.csv" --gt "$in/rec/trajectory.csv" --gt-sensor-pose nan,0,0
fail_row "capture replay --min-valid-fraction nan" "--min-valid-fraction.*not a finite number" \
  "$bin" capture replay --in "$in/cap100.bin" --out "$o/r" --min-valid-fraction nan
fail_row "chirp-doppler --alpha nan" "--alpha.*not a finite number" \
  "$bin" chirp-doppler --input "$in/rec" --alpha nan
fail_row "diagnose --alpha inf" "--alpha.*not a finite number" \
  "$bin" diagnose --recording "$in/rec" --out "$o/d" --alpha inf
fail_row "bag --rotation-hz nan" "--rotation-hz.*not a finite number" \
  "$bin" bag -i "$in/rec" -o "$o/x.bag" --rotation-hz nan
fail_row "--threads -1 (readable range)" "--threads: -1 is below the minimum 0" \
  "$bin" odometry -i "$in/rec" -o "$o/p.csv" --threads -1
fail_row "--range-resolution 0" "--range-resolution: 0 must be greater than 0" \
  "$bin" odometry -i "$in/rec" -o "$o/p.csv" --range-resolution 0
fail_row "simulate --scans -1" "--scans: -1 is below the minimum 1" \
  "$bin" simulate --scene city --scans -1 --out "$o/s"
fail_row "diagnose --appearance-split blocks:7" "blocks:7.*must be an even" \
  "$bin" diagnose --recording "$in/rec" --out "$o/d" --appearance-split blocks:7
fail_row "diagnose --max-scans 0" "--max-scans: 0 is not a count of scans" \
  "$bin" diagnose --recording "$in/rec" --out "$o/d" --max-scans 0
fail_row "diagnose --render-seeds 0" "--render-seeds: 0 is below the minimum 1" \
  "$bin" diagnose --recording "$in/rec" --out "$o/d" --render-seeds 0
fail_row "diagnose --appearance-fit-seeds 65" "--appearance-fit-seeds: 65 is above the maximum 64" \
  "$bin" diagnose --recording "$in/rec" --out "$o/d" --appearance-fit-seeds 65
fail_row "realism --render-seeds 0" "--render-seeds: 0 is below the minimum 1" \
  "$bin" realism --no-real --scene city --scans 1 --render-seeds 0
fail_row "realism --render-seeds 2.5" "--render-seeds" \
  "$bin" realism --no-real --scene city --scans 1 --render-seeds 2.5
fail_row "localize --global-stride 0" "--global-stride: 0 is below the minimum 1" \
  "$bin" localize --map "$in/rec" --map-poses "$in/rec/trajectory.csv" --input "$in/rec" --out "$o/l.csv" --global-stride 0
fail_row "pipeline range printed readably" "parameter 'zq' = -3 is outside \[0, [0-9.]+\]" \
  "$bin" odometry -i "$in/rec" -o "$o/p.csv" --zq -3

# ---- 4. format guesses and shapes -------------------------------------------------------------
fail_row "narrow PNG (12 columns)" "cannot tell the scan format: .*1547131046353776.png is 12 x 400 .*give --format" \
  "$bin" odometry -q -i "$in/narrow" -o "$o/p.csv"
fail_row "400 x 200000 PNG" "cannot tell the scan format: .*400 x 200000.*--format" \
  "$bin" odometry -q -i "$in/tall" -o "$o/p.csv"
fail_row "400 x 200000 PNG as radiate" "000001.png: 200000 range bins \(rows\)" \
  "$bin" odometry -q -i "$in/tall" -o "$o/p.csv" --format radiate
fail_row "MulRan CSV cut in its first line" "1564718976161407002.csv: 1 azimuths \(lines\)" \
  "$bin" odometry -q -i "$in/mulran_cut" -o "$o/p.csv"
fail_row "PNG and CSV scans in one folder" "mixed: cannot tell the scan format: it holds both .png .*and .csv" \
  "$bin" odometry -q -i "$in/mixed" -o "$o/p.csv"

# ---- 5. silent wrong results -------------------------------------------------------------------
fail_row "diagnose with all-zero stamps" "zerostamps: the azimuth stamps carry no time" \
  "$bin" diagnose --recording "$in/zerostamps" --out "$o/d" --format oxford --timing-only
fail_row "diagnose with a trajectory of another time" "late_trajectory.csv covers .* they do not overlap" \
  "$bin" diagnose --recording "$in/rec" --trajectory "$in/late_trajectory.csv" --world "$in/rec/world.json" --out "$o/d"
fail_row "realism without its real-data folder" "nonexistent: no such folder of real samples" \
  "$bin" realism --realdata "$in/nonexistent" --scene city --scans 1
fail_row "realism with an empty real-data folder" "real_empty: no real samples found" \
  "$bin" realism --realdata "$in/real_empty" --scene city --scans 1
fail_row "realism with a corrupt real sample" "real_bad/mulran/1564718976161407002.csv: line 1" \
  "$bin" realism --realdata "$in/real_bad" --scene city --scans 1
fail_row "realism --min-range above --max-range" "--min-range 50 m is not below --max-range 10 m" \
  "$bin" realism --realdata "$in/real_empty" --min-range 50 --max-range 10
fail_row "physics JSON with a misspelt effect" "misspelt_physics.json:1: dopler: unknown effect" \
  "$bin" simulate --scene city --scans 1 --physics "$in/misspelt_physics.json" --out "$o/s"

# ---- 6. unclear errors made clear -----------------------------------------------------------
fail_row "scan of 10 rows" "1547131046353776.png: 10 azimuths \(rows\)" \
  "$bin" odometry -q -i "$in/rows10" -o "$o/p.csv" --format oxford
fail_row "constant encoder" "only 1 of 400 rows are valid \(399 repeat the encoder" \
  "$bin" odometry -q -i "$in/constenc" -o "$o/p.csv" --format oxford
fail_row "duplicate YAML key" "duplicate_keys.yaml:2: 'zq' given twice \(also on line 1\)" \
  "$bin" odometry -i "$in/rec" -o "$o/p.csv" --config "$in/duplicate_keys.yaml"
fail_row "localize --config sets loc_nndr" "loc_nan.yaml:1: parameter 'loc_nndr': 'nan' is not a finite number" \
  "$bin" localize --map "$in/rec" --map-poses "$in/rec/trajectory.csv" --input "$in/rec" --out "$o/l.csv" --config "$in/loc_nan.yaml"
fail_row "eval --plot x.txt" "x.txt: not an image file name" \
  "$bin" eval --est "$in/est.csv" --gt "$in/rec/trajectory.csv" --plot "$o/x.txt"
fail_row "header-only CSV" "header_only.csv: a header but no poses" \
  "$bin" eval --est "$in/header_only.csv" --gt "$in/rec/trajectory.csv"
warn_row "dangling link counted" "dangling/radar/1.png: dangling link skipped" \
  "$bin" odometry -q -i "$in/dangling" -o "$o/p.csv"

# ---- 5b. the tool's own round trip: --covariance-out read back by eval (epoch stamps) ----------
rows=$((rows + 1))
if "$bin" odometry -q -i "$in/epoch" -o "$o/e.csv" --covariance-out "$o/c.csv" --estimator keyframe > /dev/null 2> "$err" &&
   "$bin" eval --est "$o/e.csv" --gt "$in/epoch/trajectory.csv" --covariance "$o/c.csv" > "$out/eval.txt" 2>> "$err" &&
   grep -q "covariance honesty" "$out/eval.txt" && head -2 "$o/c.csv" | tail -1 | grep -Eq '^15471310[0-9]{2}\.[0-9]{9},'; then
  report "odometry --covariance-out -> eval --covariance (epoch stamps)" ""
else
  report "odometry --covariance-out -> eval --covariance (epoch stamps)" "round trip failed"
fi
rm -rf "${o:?}"/*

echo "$((rows - failures)) of $rows rows pass"
[[ $failures -eq 0 ]]
