#!/usr/bin/env bash
# The README's main job: installs the Debian packages, builds, then runs the live ROS pipeline
# on the simulator end to end -- `spinradar serve` streams a built-in scene with the Navtech
# TCP protocol on loopback, the driver, feature and estimator nodelets run in one nodelet
# manager -- and prints the drift of the published odometry against the scene's true
# trajectory. Then it plays the recorded scans back from a bag as fast as the pipeline keeps
# up, and prints latency and CPU per scan for both runs.
#   SPINRADAR_DEMO_SECONDS  length of the live run in seconds (default 60)
#   SPINRADAR_DEMO_SCENE    city, out_and_back or tight_turns (default city)
#   SPINRADAR_DEMO_RATE     bag playback speed factor (default 25, i.e. 100 scans/s offered)
#   SPINRADAR_DEMO_ESTIMATOR rigid, mc, mc_doppler, refined or keyframe (default: config/spinradar.yaml)
#   SPINRADAR_DEMO_SKIP_BUILD=1  use the existing build as is
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
if [ "${SPINRADAR_DEMO_SKIP_BUILD:-0}" != 1 ]; then
  bash "$root/scripts/install_deps.sh"
  bash "$root/scripts/build.sh"
fi
build="${SPINRADAR_BUILD_DIR:-$root/build}"
seconds="${SPINRADAR_DEMO_SECONDS:-60}"
scene="${SPINRADAR_DEMO_SCENE:-city}"
play_rate="${SPINRADAR_DEMO_RATE:-25}"
estimator="${SPINRADAR_DEMO_ESTIMATOR:-}"
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
  estimator:="$estimator" monitor:=true odom_csv:="$out/live_odom.csv" summary:="$out/live_summary.json" \
  > "$out/live.log" 2>&1 & live=$!; pids+=($live)
sleep "$seconds"
kill -INT "$live" "$rec"; wait "$live" "$rec" || true

echo "[demo] drift of the live odometry against the true trajectory:"
"$cli" simulate --scene "$scene" --scans 1 --out "$out/truth" > /dev/null
"$cli" eval --est "$out/live_odom.csv" --gt "$out/truth/trajectory.csv" --step 4 \
  --json "$out/live_eval.json" | tee "$out/live_eval.txt"

echo "[demo] live run on the wall clock (as a real sensor stamps), for latency from the last azimuth"
roslaunch spinradar sim.launch scene:="$scene" rate:=1 sim_clock:=false port:=$(( sensor_port + 1 )) \
  estimator:="$estimator" monitor:=true summary:="$out/wallclock_summary.json" > "$out/wallclock.log" 2>&1 & wall=$!; pids+=($wall)
sleep 20
kill -INT "$wall"; wait "$wall" || true

echo "[demo] bag playback of the live run's scans at ${play_rate}x (simulated time)"
roslaunch spinradar rosbag.launch bag:="$out/live.bag" rate:="$play_rate" delay:=3 monitor:=true \
  estimator:="$estimator" \
  odom_csv:="$out/playback_odom.csv" summary:="$out/playback_summary.json" \
  > "$out/playback.log" 2>&1 || true

/usr/bin/python3 - "$out" <<'PY'
import json, sys
out = sys.argv[1]
def load(name):
    try:
        return json.load(open('%s/%s' % (out, name)))
    except (OSError, ValueError):
        return None
ev = load('live_eval.json')
print('[demo] ---- summary ----')
if ev:
    e = ev[0]
    print('[demo] live ROS pipeline on the simulator: %d scans, %.0f m, drift against truth %.2f %% '
          'and %.4f deg/m (KITTI-style, %d segments of 100-800 m); end-point error %.1f m'
          % (e['poses'], e['path_length_m'], e['t_err_pct'], e['r_err_deg_per_m'], e['segments'],
             e['final_error_m']))
for name, what in (('live', '4 Hz live, simulator clock'), ('wallclock', '4 Hz live, wall clock'),
                   ('playback', 'bag playback, as fast as it plays')):
    s = load(name + '_summary.json')
    if not s or not s.get('scans'):
        print('[demo] %s: no measurements' % what); continue
    line = '[demo] %-34s %4d scans at %5.2f Hz: CPU %5.1f ms/scan; scan message -> odometry median %.1f ms (max %.1f)' % (
        what, s['scans'], s['scan_rate_hz'], s['cpu_ms_per_scan'],
        s['latency_scan_message_ms']['median'], s['latency_scan_message_ms']['max'])
    if name == 'wallclock':
        a = s['latency_last_azimuth_ms']
        line += '; last azimuth -> odometry median %.1f ms (max %.1f)' % (a['median'], a['max'])
    print(line)
PY
