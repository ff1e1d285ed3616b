#!/usr/bin/env bash
# The main job of `make run` (called by the Makefile with the workspace sourced): the full ROS
# pipeline of launch/demo.launch under sim time, in one nodelet manager:
#   driver_sim (config/scenarios/demo.yaml: calibration plateaus, rest, verification plateaus)
#   -> processor (working copy of the parameter file) and a processor keeping the uncalibrated model
#   -> calibrator (dual rate): accepted result written atomically, processor reloaded
#   -> session_monitor: outputs against ground truth on the verification profile.
# Prints the summary; its last line is `nonlinearity_ppm before=<X> after=<Y>`.
# Then the HTML calibration report of the session (run_output/report.html), checked to show that line.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/run_output"
mkdir -p "$out"
cp "$root/config/params_uncalibrated.yaml" "$out/params.yaml"
rm -f "$out/params.yaml.bak" "$out/summary.txt" "$out/summary.txt.yaml" "$out/report.html"
echo "make run: simulating ~3000 s of turntable session through the ROS pipeline (about 1.5 min)..." >&2
start=$(date +%s)
# A private master port, so a roscore the user already runs is left alone.
export ROS_MASTER_URI="http://localhost:$(( 20000 + RANDOM % 20000 ))"
roslaunch -p "${ROS_MASTER_URI##*:}" hrg_gyro demo.launch \
  parameter_file:="$out/params.yaml" summary_file:="$out/summary.txt" time_scale:=40 \
  > "$out/roslaunch.log" 2>&1 || true
if [ ! -s "$out/summary.txt" ]; then
  echo "make run: the pipeline produced no summary; the end of $out/roslaunch.log:" >&2
  tail -n 30 "$out/roslaunch.log" >&2
  exit 1
fi
echo "make run: done in $(( $(date +%s) - start )) s; calibrated parameters in $out/params.yaml," \
     "calibration report in $out/params.dual_rate.report.yaml, logs in $out/roslaunch.log" >&2
# The report needs the session as a bag: the same scenario and seed through `hrg_bag simulate` (the
# turntable profile and the rest for the Allan deviation); the calibration is the pipeline's own.
echo "make run: writing the HTML calibration report (the session re-simulated as a bag, about 45 s)..." >&2
hrg_bag="$(catkin_find --first-only --libexec hrg_gyro hrg_bag)"
"$hrg_bag" simulate --scenario "$root/config/scenarios/demo.yaml" --out "$out/session.bag" > "$out/report.log" 2>&1
/usr/bin/python3 "$root/scripts/hrg_report.py" "$out/params.dual_rate.report.yaml" --bag "$out/session.bag" \
  --params "$out/params.yaml" --verification "$out/summary.txt.yaml" --spec "$root/config/report_spec.yaml" \
  --title "Calibration report: make run session" --out "$out/report.html" >> "$out/report.log" 2>&1
# The report must show the figures this job prints.
printed="$(grep '^nonlinearity_ppm ' "$out/summary.txt" | sed 's/^nonlinearity_ppm //')"
shown="$(/usr/bin/python3 - "$out/report.html" <<'PY'
import re, sys
page = open(sys.argv[1]).read()
get = lambda key: re.search(r'id="verification-%s">([^<]*)<' % key, page).group(1)
print("before=%s after=%s" % (get("before"), get("after")))
PY
)"
if [ "$printed" != "$shown" ]; then
  echo "make run: the report shows $shown, the summary printed $printed" >&2
  exit 1
fi
echo "make run: report in $out/report.html shows $shown" >&2
cat "$out/summary.txt"
