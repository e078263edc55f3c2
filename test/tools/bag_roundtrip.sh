#!/usr/bin/env bash
# Scan folder -> rosbag -> scan folder must give back the same scans: odometry over the
# original and the round-tripped folder must write identical poses, and the stamps must
# survive. Exit 77 (skip) when the Oxford sample is absent.
# Usage: bag_roundtrip.sh SPINRADAR_BIN SHARED_DIR OUT_DIR
set -euo pipefail
bin="$1"; shared="$2"; out="$3"
seq="$shared/realdata/oxford_2019-01-10-14-36-48"
if [[ ! -d "$seq/radar" ]]; then echo "SKIP: Oxford sample not found at $seq" >&2; exit 77; fi
rm -rf "$out"; mkdir -p "$out"
"$bin" bag --input "$seq" --out "$out/scans.bag" --topic /radar/scan
"$bin" bag --input "$out/scans.bag" --out "$out/back"
diff <(ls "$seq/radar") <(ls "$out/back/radar")
diff <(awk '{print $1}' "$seq/radar.timestamps") <(awk '{print $1}' "$out/back/radar.timestamps")
"$bin" odometry -q --input "$seq" --out "$out/original.csv" --estimator rigid
"$bin" odometry -q --input "$out/back" --out "$out/roundtrip.csv" --estimator rigid
diff "$out/original.csv" "$out/roundtrip.csv"
echo "ok: $(ls "$out/back/radar" | wc -l) scans round-tripped through $out/scans.bag"
