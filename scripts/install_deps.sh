#!/usr/bin/env bash
# Installs the Debian packages hrg_gyro needs, only those missing (idempotent; run as root or with
# sudo available). Arguments name extra packages. ROS 1 comes from Debian bookworm itself, not from a ROS apt source.
set -euo pipefail

PACKAGES=(
  build-essential cmake
  ros-core-dev python3-rostest python3-roslaunch python3-rosbag rosbash rosout
  python3-rostopic python3-rosnode python3-rosparam python3-rosmaster python3-rosservice
  libeigen3-dev libyaml-cpp-dev libgtest-dev libbenchmark-dev
  libnodeletlib-dev libnodeletlib-tools libnodelet-dev pluginlib-dev
  libdiagnostic-updater-dev libstd-srvs-dev libsensor-msgs-dev
  python3-std-srvs python3-sensor-msgs python3-diagnostic-msgs python3-yaml
  python3-numpy python3-matplotlib python3-jinja2 chromium
  libcli11-dev
  tf2-tools libtf2-ros-dev python3-rosunit catkin-lint python3-nodelet clang-format
)
# libcli11-dev: the command-line parser of hrg_bag and hrg_session (header only). Its rosdep key,
# cli11, is recent in rosdistro and absent from older rosdep databases (Debian's python3-rosdep2
# file among them), so CMakeLists.txt finds the header itself and this list installs it.
# tf2-tools and libtf2-ros-dev: static_transform_publisher and the tf2_ros package of the example
# stack launch; python3-rosunit and catkin-lint: the install-space and package checks of make test;
# python3-nodelet: the nodelet manager's list service in two_gyros.test; clang-format: the format check.
# python3-jinja2: the HTML calibration report (scripts/hrg_report.py); chromium: the report test renders
# it headless as a reader's browser would.
# Extra packages for one target, e.g. `install_deps.sh clang-14 libclang-rt-14-dev` for `make fuzz`.
PACKAGES+=("$@")

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#PACKAGES[@]} Debian packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
