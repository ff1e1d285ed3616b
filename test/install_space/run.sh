#!/usr/bin/env bash
# The install-space check of `make test`: installs the package into a fresh prefix and runs
# install_space_test.py with only that install space sourced (no devel space on any path). Its
# results land in the workspace's test results, where catkin_test_results counts them.
#   bash test/install_space/run.sh WORKSPACE
set -euo pipefail
ws="$(cd "$1" && pwd)"
src="$(cd "$(dirname "$0")/../.." && pwd)"
prefix="$ws/install"
rm -rf "$prefix"
echo "install_space: catkin_make install into $prefix"
# A clean environment: nothing sourced, Debian's python3 first (catkin_pkg).
env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 bash -c \
  "cd '$ws' && catkin_make -DPYTHON_EXECUTABLE=/usr/bin/python3 -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX='$prefix' install" \
  > "$ws/install_space.log" 2>&1 || { tail -n 40 "$ws/install_space.log"; exit 1; }
results="$ws/build/test_results"
mkdir -p "$results/hrg_gyro"
env -i HOME="$HOME" PATH=/usr/bin:/bin LANG=C.UTF-8 HRG_SOURCE_DIR="$src" HRG_WORKSPACE="$ws" \
  ROS_TEST_RESULTS_DIR="$results" bash -c \
  "source '$prefix/setup.bash' && /usr/bin/python3 '$src/test/install_space/install_space_test.py'"
