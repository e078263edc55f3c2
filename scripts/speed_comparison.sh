#!/usr/bin/env bash
# Whole-process speed of `spinradar odometry` (README "Speed"): the first SCANS (40) scans of a
# simulated Oxford-layout city drive, the whole process timed from the shell (start-up, PNG
# decoding, features, matching, estimation, writing poses):
#   - one thread, pinned to one core with taskset: ms per scan (wall and CPU)
#   - two threads (scans decoded in the background): scans per second
#   - peak resident memory (/usr/bin/time -v)
# CFEAR and the paper's code run side by side on the same folder when their commands are given
# (neither is part of this repository: build them from their public code, README "Speed");
# otherwise the issue's figures, measured elsewhere, are printed and labelled so. Each figure is the best of REPEAT runs (the machine may be shared), with the median.
# Usage: scripts/speed_comparison.sh [WORK_DIR]   (default build/speed_comparison)
# Env: SPINRADAR_BIN, SCANS (40), REPEAT (5), CORE (0: the core for the one-thread run),
#      CFEAR_CMD / PAPER_CMD: command lines with {radar} (folder of PNGs) and {out} (a folder for
#      their output), or CFEAR_BIN / PAPER_BIN: run as "$BIN {radar} {out}".
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
work="${1:-$root/build/speed_comparison}"
scans="${SCANS:-40}"
repeat="${REPEAT:-5}"
core="${CORE:-0}"
source "$root/scripts/cli_path.sh"
bin="$(spinradar_cli_path "$root")"
[[ -x "$bin" ]] || { echo "error: spinradar CLI not found (build it or set SPINRADAR_BIN)" >&2; exit 1; }
command -v taskset > /dev/null || { echo "error: taskset (util-linux) needed" >&2; exit 1; }
[[ -x /usr/bin/time ]] || { echo "error: /usr/bin/time (package time) needed" >&2; exit 1; }
mkdir -p "$work"
drive="$work/city_$scans"
if [[ ! -f "$drive/radar.timestamps" ]] || [[ $(ls "$drive/radar" | wc -l) -ne $scans ]]; then
  rm -rf "$drive"
  "$bin" simulate --scene city --scans "$scans" --out "$drive" 2> "$work/simulate.log"
fi

# run NAME CMD...: REPEAT runs; prints "NAME wall_s cpu_s maxrss_kb" of each run to $work/NAME.runs
run() {
  local name="$1"; shift
  : > "$work/$name.runs"
  for ((i = 0; i < repeat; i++)); do
    /usr/bin/time -v -o "$work/$name.time" "$@" > /dev/null 2> "$work/$name.log" || {
      echo "error: $name failed, see $work/$name.log" >&2; exit 1; }
    awk -v n="$name" '
      /Elapsed \(wall clock\)/ { split($NF, t, ":"); wall = (length(t) == 3) ? t[1]*3600 + t[2]*60 + t[3] : t[1]*60 + t[2] }
      /User time/ { user = $NF } /System time/ { sys = $NF } /Maximum resident/ { rss = $NF }
      END { printf "%s %.3f %.3f %d\n", n, wall, user + sys, rss }' "$work/$name.time" >> "$work/$name.runs"
  done
}
# summary NAME LABEL: best and median per scan over the runs
summary() {
  sort -k2 -g "$work/$1.runs" | awk -v n="$scans" -v label="$2" '
    { wall[NR] = $2; cpu[NR] = $3; rss[NR] = $4 }
    END { m = int((NR + 1) / 2); best_cpu = cpu[1]; for (i = 1; i <= NR; i++) if (cpu[i] < best_cpu) best_cpu = cpu[i]
          max_rss = 0; for (i = 1; i <= NR; i++) if (rss[i] > max_rss) max_rss = rss[i]
          printf "%-38s %8.1f %8.1f %8.1f %8.1f %8.1f\n", label, 1000 * wall[1] / n, 1000 * wall[m] / n,
                 1000 * best_cpu / n, n / wall[1], max_rss / 1024 }'
}

echo "spinradar: $bin"
echo "drive: $drive ($scans scans of the simulated city route, Oxford PNG layout); best of $repeat runs"
run one_thread taskset -c "$core" "$bin" odometry --input "$drive" --out "$work/poses_1.csv" --threads 1 --quiet
run two_threads "$bin" odometry --input "$drive" --out "$work/poses_2.csv" --threads 2 --quiet
cmp -s "$work/poses_1.csv" "$work/poses_2.csv" || echo "warning: --threads 1 and 2 poses differ" >&2
printf "%-38s %8s %8s %8s %8s %8s\n" "whole process" "ms/scan" "(median)" "cpu ms" "scans/s" "peak MB"
summary one_thread "spinradar, 1 thread (taskset 1 core)"
summary two_threads "spinradar, 2 threads"
grep -E "load|pipeline total" "$work/one_thread.log" | sed 's/^/  one-thread run, inside: /'
# The same on the first 2 scans: splits the CPU time into a one-off part (start-up, tables, first
# page faults) and the cost of each further scan.
small="$work/first_2/radar"
rm -rf "$work/first_2"; mkdir -p "$small"
for f in $(ls "$drive/radar" | head -2); do ln -s "$drive/radar/$f" "$small/$f"; done
run two_scans taskset -c "$core" "$bin" odometry --input "$small" --out "$work/poses_first_2.csv" --threads 1 --quiet
best_cpu() { sort -k3 -g "$work/$1.runs" | head -1 | awk '{ print $3 }'; }
awk -v c2="$(best_cpu two_scans)" -v cn="$(best_cpu one_thread)" -v n="$scans" 'BEGIN {
  per = (cn - c2) / (n - 2); printf "  one thread, CPU: %.0f ms one-off (start-up, tables) + %.1f ms per scan\n",
  1000 * (c2 - 2 * per), 1000 * per }'

side_by_side() {  # NAME CMD_TEMPLATE
  local name="$1" tmpl="$2" out="$work/$1_out"
  mkdir -p "$out"
  local cmd="${tmpl//\{radar\}/$drive/radar}"
  cmd="${cmd//\{out\}/$out}"
  run "$name" taskset -c "$core" bash -c "$cmd"
  summary "$name" "$name (taskset 1 core)"
}
any=0
[[ -n "${CFEAR_BIN:-}" && -z "${CFEAR_CMD:-}" ]] && CFEAR_CMD="$CFEAR_BIN {radar} {out}"
[[ -n "${PAPER_BIN:-}" && -z "${PAPER_CMD:-}" ]] && PAPER_CMD="$PAPER_BIN {radar} {out}"
if [[ -n "${CFEAR_CMD:-}" ]]; then side_by_side cfear "$CFEAR_CMD"; any=1; fi
if [[ -n "${PAPER_CMD:-}" ]]; then side_by_side paper "$PAPER_CMD"; any=1; fi
if [[ $any == 0 ]]; then
  cat <<'EOF'
Not run here (no CFEAR_CMD/CFEAR_BIN, PAPER_CMD/PAPER_BIN given; see README "Speed" for how
they were built). MEASURED ELSEWHERE (issue 21, same 40-scan drive, side by side, one core):
  paper's code (Burnett et al.)        123-127 ms per scan
  CFEAR-1                              28.5 ms per scan (19 ms over 400 scans)
  CFEAR-2                              21 ms per scan over 400 scans
  CFEAR-3                              33 ms per scan over 400 scans
  spinradar before issue 21            23-40 ms per scan (31.6 ms: 21.7 load, 8.5 pipeline)
EOF
fi
