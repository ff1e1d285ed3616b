#!/usr/bin/env bash
# The main job of `make run` (called by the Makefile with the workspace sourced).
# Calibrates the simulated gyro (config/scenarios/dual_rate.yaml) starting from the uncalibrated
# parameter file, writes the refreshed parameters atomically to run_output/, verifies before and
# after on config/scenarios/verification.yaml, and prints the summary; the last line is
#   nonlinearity_ppm before=<X> after=<Y>
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="$root/run_output"
mkdir -p "$out"
cp "$root/config/params_uncalibrated.yaml" "$out/params.yaml"
exec "$root/ws/devel/lib/hrg_gyro/hrg_session" \
  --calibration "$root/config/scenarios/dual_rate.yaml" \
  --verification "$root/config/scenarios/verification.yaml" \
  --params "$out/params.yaml" --out "$out/params.yaml"
