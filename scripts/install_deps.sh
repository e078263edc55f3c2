#!/usr/bin/env bash
# Installs every Debian package spinradar needs to build, test and run (Debian 12, as root).
set -euo pipefail
PKGS=(
  build-essential cmake git pkg-config
  libeigen3-dev libopencv-dev nlohmann-json3-dev libyaml-cpp-dev libcli11-dev libtbb-dev
  libdeflate-dev libspng-dev
  libgtest-dev libgmock-dev libbenchmark-dev clang libclang-rt-14-dev
  catkin ros-core-dev ros-message-generation libnodeletlib-dev libnodeletlib-tools
  libtf2-ros-dev libtf2-eigen-dev librosbag-dev python3-rosbag python3-rostest python3-roslaunch
  libdynamic-reconfigure-config-init-mutex-dev python3-dynamic-reconfigure
  libsensor-msgs-dev libnav-msgs-dev libgeometry-msgs-dev libvisualization-msgs-dev
  libdiagnostic-updater-dev libcv-bridge-dev
  rosbash tf2-tools python3-tf2-ros python3-sensor-msgs python3-nodelet
  rviz xvfb xauth libgl1-mesa-dri imagemagick
  python3-numpy python3-opencv python3-matplotlib
)
missing=()
for p in "${PKGS[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "[spinradar] installing ${#missing[@]} Debian packages: ${missing[*]}"
  if [ "$(id -u)" != 0 ]; then echo "[spinradar] run as root (apt-get install needs it)" >&2; exit 1; fi
  apt-get update -q
  DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends "${missing[@]}"
else
  echo "[spinradar] all Debian packages present"
fi
