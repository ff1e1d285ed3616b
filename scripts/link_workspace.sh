#!/usr/bin/env bash
# Makes WORKSPACE/src/hrg_gyro the package as catkin, rospack, rosrun and roslaunch see it: a folder
# of links to each entry of the checkout, except the workspace itself (.ws) and .git.
#   bash scripts/link_workspace.sh CHECKOUT WORKSPACE
# Why not one link to the whole checkout: the workspace lives inside the checkout, so such a link
# makes a loop. rosrun searches the package with `find -L`, which then prints "File system loop
# detected" on every call and finds a copy of each executable in devel/, build/ and install/ (a
# menu to choose from instead of a program). Links per entry reach every source file and never the
# workspace. Entries added to or removed from the checkout are linked or unlinked on each build.
set -euo pipefail
root="$(cd "$1" && pwd)"
ws="$2"
pkg="$ws/src/hrg_gyro"
mkdir -p "$ws/src"
# Workspaces made before this script linked the whole checkout: replace that link by the folder.
if [ -L "$pkg" ]; then rm -f "$pkg"; fi
mkdir -p "$pkg"
shopt -s dotglob nullglob
for entry in "$root"/*; do
  name="$(basename "$entry")"
  case "$name" in
    .ws | .git) continue ;;
  esac
  ln -sfn "$entry" "$pkg/$name"
done
# Links whose entry left the checkout.
for link in "$pkg"/*; do
  if [ -L "$link" ] && [ ! -e "$link" ]; then rm -f "$link"; fi
done
