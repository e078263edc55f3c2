#!/usr/bin/env bash
# The README's main job: installs the Debian packages, builds, then runs the live ROS pipeline
# on the simulator end to end -- `spinradar serve` streams a built-in scene with the Navtech
# TCP protocol on loopback, the driver, feature and estimator nodelets run in one nodelet
# manager -- and prints the drift of the published odometry against the scene's true
# trajectory. Then it plays the recorded scans back from a bag as fast as the pipeline keeps
# up, and prints latency and CPU per scan for both runs.
#   SPINRADAR_DEMO_SECONDS  length of the live run in seconds (default 60)
#   SPINRADAR_DEMO_SCENE    city, out_and_back or tight_turns (default city)
#   SPINRADAR_DEMO_RATE     bag playback speed factor (default 8)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
bash "$root/scripts/install_deps.sh"
bash "$root/scripts/build.sh"
build="${SPINRADAR_BUILD_DIR:-$root/build}"
seconds="${SPINRADAR_DEMO_SECONDS:-60}"
scene="${SPINRADAR_DEMO_SCENE:-city}"
play_rate="${SPINRADAR_DEMO_RATE:-8}"
out="$build/demo"
rm -rf "$out" && mkdir -p "$out"
export PATH=/usr/bin:$PATH
set +u; source "$build/devel/setup.bash"; set -u
export ROS_LOG_DIR="$out/ros_log" ROS_HOME="$out/ros_home"
# A private master and sensor port on loopback, so the demo does not meet other ROS systems.
master_port=$(( 20000 + RANDOM % 10000 )); sensor_port=$(( master_port + 1 ))
export ROS_MASTER_URI="http://127.0.0.1:$master_port" ROS_IP=127.0.0.1
cli="$build/devel/lib/spinradar/spinradar"
pids=()
cleanup() { for p in "${pids[@]}"; do kill -INT "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
roscore -p "$master_port" > "$out/roscore.log" 2>&1 & pids+=($!)
for _ in $(seq 50); do rosparam list > /dev/null 2>&1 && break; sleep 0.2; done

echo "[demo] live run: scene '$scene' served on 127.0.0.1:$sensor_port at 4 Hz for $seconds s"
rosbag record -q -O "$out/live.bag" scan __name:=recorder > "$out/record.log" 2>&1 & rec=$!; pids+=($rec)
roslaunch spinradar sim.launch scene:="$scene" rate:=1 sim_clock:=true port:="$sensor_port" \
  monitor:=true odom_csv:="$out/live_odom.csv" summary:="$out/live_summary.json" \
  > "$out/live.log" 2>&1 & live=$!; pids+=($live)
sleep "$seconds"
kill -INT "$live" "$rec"; wait "$live" "$rec" || true

echo "[demo] drift of the live odometry against the true trajectory:"
"$cli" simulate --scene "$scene" --scans 1 --out "$out/truth" > /dev/null
"$cli" eval --est "$out/live_odom.csv" --gt "$out/truth/trajectory.csv" --step 4 \
  --json "$out/live_eval.json" | tee "$out/live_eval.txt"

echo "[demo] bag playback of the same scans at ${play_rate}x (simulated time)"
roslaunch spinradar rosbag.launch bag:="$out/live.bag" rate:="$play_rate" delay:=3 \
  > "$out/playback.log" 2>&1 & play=$!; pids+=($play)
sleep 2
rosrun nodelet nodelet load spinradar/PipelineMonitor spinradar_manager __name:=monitor \
  _odom_csv:="$out/playback_odom.csv" _summary:="$out/playback_summary.json" \
  > "$out/monitor.log" 2>&1 & mon=$!; pids+=($mon)
wait "$play" || true
kill -INT "$mon" 2>/dev/null || true; wait "$mon" 2>/dev/null || true

/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
ev = json.load(open(out + '/live_eval.json'))
def pick(d, *keys):
    for k in keys:
        if isinstance(d, dict) and k in d: return d[k]
    return None
print('[demo] ---- summary ----')
print('[demo] drift against truth: %s' % json.dumps(ev)[:600])
for name in ('live', 'playback'):
    try:
        s = json.load(open('%s/%s_summary.json' % (out, name)))
    except (OSError, ValueError):
        print('[demo] %s: no measurements' % name); continue
    print('[demo] %-8s %d scans at %.2f Hz, CPU %.1f ms/scan, latency scan message -> odometry '
          'median %.1f ms (max %.1f)' % (name, s['scans'], s['scan_rate_hz'], s['cpu_ms_per_scan'],
          s['latency_scan_message_ms']['median'], s['latency_scan_message_ms']['max']))
PY
