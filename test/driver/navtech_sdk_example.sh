#!/usr/bin/env bash
# Navtech's own SDK example (shared/navtech-iasdk/ReadOneRotationOfFFTData.py, a client nobody
# on this project wrote; it sends its commands with protocol version byte 0) reads one full
# rotation from `spinradar serve`. Exit 77 (ctest: skipped) when shared/ is absent.
# Usage: navtech_sdk_example.sh CLI SHARED_DIR OUT_DIR
set -uo pipefail
cli="$1"; shared="$2"; out="$3"
here="$(cd "$(dirname "$0")" && pwd)"
example="$shared/navtech-iasdk/ReadOneRotationOfFFTData.py"
if [[ ! -f "$example" ]]; then
  echo "SKIP: $example not found (needs shared/ beside the clone)"; exit 77
fi
py=""
for c in /usr/bin/python3 python3; do
  if command -v "$c" >/dev/null && "$c" -c 'import numpy, cv2, matplotlib' 2>/dev/null; then py="$c"; break; fi
done
if [[ -z "$py" ]]; then
  echo "error: no python3 with numpy, cv2 and matplotlib (scripts/install_deps.sh installs" \
       "python3-numpy python3-opencv python3-matplotlib)" >&2
  exit 1
fi
mkdir -p "$out"
# Encoders at a real CIR204-H's phase (13, 27, ..., 5599): the example turns them into rows with
# int(), which with phase 0 puts 18 of the 400 rows one row down (float truncation).
"$cli" serve --scene city --port 0 --rate 1 --encoder-phase 13 > "$out/serve.log" 2>&1 &
serve_pid=$!
trap 'kill "$serve_pid" 2>/dev/null; wait "$serve_pid" 2>/dev/null' EXIT
port=""
for _ in $(seq 1 600); do
  port="$(sed -n 's/.* on 127\.0\.0\.1:\([0-9]*\) .*/\1/p' "$out/serve.log" | head -1)"
  [[ -n "$port" ]] && break
  kill -0 "$serve_pid" 2>/dev/null || break
  sleep 0.1
done
if [[ -z "$port" ]]; then
  echo "error: spinradar serve did not start:" >&2; cat "$out/serve.log" >&2; exit 1
fi
cd "$out" && MPLBACKEND=Agg timeout 60 "$py" "$here/navtech_sdk_harness.py" "$example" 127.0.0.1 "$port"
rc=$?
echo "--- spinradar serve log ---"
cat "$out/serve.log"
exit $rc
