#!/usr/bin/env bash
# A calibrated sensor file's "reference_scene" (include/spinradar/sim/reference_scene.hpp) at the
# CLI, with known truth: the scene a command renders is told by the world it writes and by the
# scans themselves.
# - simulate --sensor oxford without --scene renders city_heights (the shipped file's key): the
#   same world.json and the same scans as --scene city_heights.
# - an explicit --scene wins: --scene city gives the city's world.json, not city_heights'.
# - the key does not change a render: the file without the key, given --scene city_heights,
#   gives the same scans; a recording's sensor.json carries the key only when the file has it.
# - a file without the key behaves as before: simulate without --scene is the old error, serve
#   and realism keep their old default scenes.
# - a bad value is refused naming the file, line and key.
# - realism and serve take the key as their default; diagnose's appearance stage too, and it
#   writes its --appearance-scene into sensor_fitted.json (none for "recording").
# Usage: reference_scene.sh SPINRADAR_BIN OUT_DIR SOURCE_DIR
set -euo pipefail
bin="$1"; out="$2"; src="$3"
rm -rf "$out"; mkdir -p "$out"
fail() { echo "FAIL: $*" >&2; exit 1; }
same_scans() {  # two recordings: the same PNGs, byte for byte
  local a b n=0
  for a in "$1"/radar/*.png; do
    b="$2/radar/$(basename "$a")"
    cmp -s "$a" "$b" || return 1
    n=$((n + 1))
  done
  [[ $n -gt 0 ]]
}
ox="$src/config/sensors/oxford.json"
grep -q '"reference_scene": "city_heights"' "$ox" || fail "$ox has no reference_scene city_heights"

# simulate: the default scene is the file's; the explicit one wins.
sim() { "$bin" simulate --seed 3 --first 40 --scans 2 "$@"; }
sim --sensor oxford --out "$out/default" 2> "$out/default.log"
grep -q "scene 'city_heights' (the sensor file's reference_scene)" "$out/default.log" \
  || { cat "$out/default.log"; fail "simulate did not say it took the reference scene"; }
sim --sensor oxford --scene city_heights --out "$out/explicit_heights" 2> /dev/null
sim --sensor oxford --scene city --out "$out/explicit_city" 2> /dev/null
"$bin" simulate --scene city_heights --scans 1 --out "$out/world_heights" 2> /dev/null
"$bin" simulate --scene city --scans 1 --out "$out/world_city" 2> /dev/null
cmp -s "$out/default/world.json" "$out/world_heights/world.json" || fail "default scene is not city_heights"
cmp -s "$out/explicit_city/world.json" "$out/world_city/world.json" || fail "--scene city did not win"
cmp -s "$out/world_city/world.json" "$out/world_heights/world.json" && fail "city and city_heights worlds are equal: the test proves nothing"
same_scans "$out/default" "$out/explicit_heights" || fail "default and --scene city_heights scans differ"
same_scans "$out/default" "$out/explicit_city" && fail "--scene city rendered the same scans as city_heights"
grep -q '"reference_scene": "city_heights"' "$out/default/sensor.json" || fail "recording's sensor.json lost the key"

# The key itself changes no render, and a file without it is written without it.
/usr/bin/env python3 - "$ox" "$out/nokey.json" "$out/bad.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
del j["reference_scene"]
json.dump(j, open(sys.argv[2], "w"), indent=1, sort_keys=True)
j["reference_scene"] = "city_hieghts"
open(sys.argv[3], "w").write(json.dumps(j, indent=1, sort_keys=True) + "\n")
PY
sim --sensor "$out/nokey.json" --scene city_heights --out "$out/nokey_heights" 2> /dev/null
same_scans "$out/default" "$out/nokey_heights" || fail "the key changed the scans"
grep -q reference_scene "$out/nokey_heights/sensor.json" && fail "sensor.json of a file without the key has one"
bash "$src/test/tools/expect_error.sh" "give --scene NAME" \
  "$bin" simulate --sensor "$out/nokey.json" --scans 1 --out "$out/never1" > /dev/null 2>&1 \
  || fail "a file without the key did not need --scene"
line=$(grep -n reference_scene "$out/bad.json" | cut -d: -f1)
bash "$src/test/tools/expect_error.sh" "bad.json:$line: reference_scene: 'city_hieghts' is not a built-in scene" \
  "$bin" simulate --sensor "$out/bad.json" --scans 1 --out "$out/never2" \
  || fail "a misspelt reference scene was not refused with file, line and key"

# realism: one column, the reference scene, unless --scene; the old three without the key.
"$bin" realism --no-real --scans 1 --sensor oxford > "$out/realism_default.txt" 2> /dev/null
grep -q "city_heights (sim)" "$out/realism_default.txt" || fail "realism did not take the reference scene"
grep -q "out_and_back (sim)" "$out/realism_default.txt" && fail "realism rendered its old default list"
"$bin" realism --no-real --scans 1 --sensor oxford --scene city > "$out/realism_city.txt" 2> /dev/null
grep -q "| city (sim)\|city (sim)" "$out/realism_city.txt" || fail "realism --scene city did not win"
grep -q "city_heights (sim)" "$out/realism_city.txt" && fail "realism --scene city rendered city_heights"
"$bin" realism --no-real --scans 1 --sensor "$out/nokey.json" > "$out/realism_nokey.txt" 2> /dev/null
for s in city out_and_back tight_turns; do
  grep -q "$s (sim)" "$out/realism_nokey.txt" || fail "realism without the key lost scene $s"
done

# serve: says which scene it serves (stopped after a moment).
serve_scene() {  # serve args... -> the scene it announced (waits up to 120 s, then stops it)
  : > "$out/serve.log"
  "$bin" serve --port 0 "$@" 2> "$out/serve.log" > /dev/null &
  local pid=$! k
  for k in $(seq 240); do
    grep -q "^serve: scene" "$out/serve.log" && break
    kill -0 "$pid" 2> /dev/null || break
    sleep 0.5
  done
  kill "$pid" 2> /dev/null || true
  wait "$pid" 2> /dev/null || true
  sed -n "s/^serve: scene '\([a-z_]*\)'.*/\1/p" "$out/serve.log" | head -1
}
[[ "$(serve_scene --sensor oxford)" == city_heights ]] || { cat "$out/serve.log"; fail "serve did not take the reference scene"; }
[[ "$(serve_scene --sensor oxford --scene tight_turns)" == tight_turns ]] || fail "serve --scene did not win"
[[ "$(serve_scene --sensor "$out/nokey.json")" == city ]] || fail "serve without the key is not city"

# diagnose: the appearance stage re-simulates the reference scene by default and writes the
# scene it ran in into sensor_fitted.json; an own-scene fit writes no key. On a small sensor
# (100 azimuths, 600 bins; the stage takes the recording's geometry) to keep the test short.
/usr/bin/env python3 - "$ox" "$out/small.json" "$out/small_nokey.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
j.update(azimuths=100, bins=600)
json.dump(j, open(sys.argv[2], "w"), indent=1, sort_keys=True)
del j["reference_scene"]
json.dump(j, open(sys.argv[3], "w"), indent=1, sort_keys=True)
PY
sim --sensor "$out/small.json" --out "$out/small_rec" 2> /dev/null
diag() {  # name args...
  local name="$1"; shift
  "$bin" diagnose --recording "$out/small_rec/radar" --appearance-iterations 0 \
    --appearance-curve-iterations 0 --appearance-curve-starts 1 --appearance-scans 1 \
    --appearance-no-holdout --out "$out/$name" "$@" > "$out/$name.log" 2>&1 \
    || { cat "$out/$name.log"; fail "diagnose $name failed"; }
  /usr/bin/env python3 -c 'import json,sys; print(json.load(open(sys.argv[1])).get("reference_scene", "-"))' \
    "$out/$name/appearance/sensor_fitted.json"
}
[[ "$(diag d_default --sensor "$out/small.json")" == city_heights ]] || fail "diagnose did not default to the reference scene"
[[ "$(diag d_city --sensor "$out/small.json" --appearance-scene city)" == city ]] || fail "diagnose --appearance-scene city did not win"
[[ "$(diag d_nokey --sensor "$out/small_nokey.json")" == city ]] || fail "diagnose without the key is not city"
[[ "$(diag d_own --sensor "$out/small.json" --appearance-scene recording)" == - ]] || fail "an own-scene fit wrote a reference scene"
echo "ok: reference_scene"
