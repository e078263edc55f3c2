#!/usr/bin/env bash
# Shows that the rviz config works: starts the live pipeline on the simulator (sim.launch) with
# rviz under Xvfb, lets it run, and saves a screenshot of the whole screen.
# Usage: scripts/rviz_screenshot.sh [output.png] [seconds]   (build first: scripts/build.sh)
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${SPINRADAR_BUILD_DIR:-$root/build}"
out="$(realpath -m "${1:-$build/rviz_screenshot.png}")"
seconds="${2:-25}"
export PATH=/usr/bin:$PATH
set +u; source "$build/devel/setup.bash"; set -u
log_dir="$build/rviz_screenshot_log"
mkdir -p "$log_dir"
export ROS_LOG_DIR="$log_dir" ROS_HOME="$log_dir"
# roslaunch starts a private master on this loopback port; the sensor port is next to it.
master_port=$(( 20000 + RANDOM % 10000 ))
export ROS_MASTER_URI="http://127.0.0.1:$master_port" ROS_IP=127.0.0.1
export SPINRADAR_SHOT_OUT="$out" SPINRADAR_SHOT_SECONDS="$seconds" SPINRADAR_SHOT_PORT=$(( master_port + 1 ))
xvfb-run -a -s "-screen 0 1280x1024x24" bash -c '
  roslaunch spinradar sim.launch rviz:=true port:=$SPINRADAR_SHOT_PORT > "$ROS_LOG_DIR/launch.log" 2>&1 &
  L=$!
  sleep "$SPINRADAR_SHOT_SECONDS"
  /usr/bin/import -window root "$SPINRADAR_SHOT_OUT"
  kill -INT $L; wait $L || true'
echo "[rviz_screenshot] saved $out"
