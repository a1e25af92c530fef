#!/usr/bin/env bash
# Prints docs/control.md's table of issue 23's plants as measured now: runs ctest's PlantSweep
# (each plant identified, then a step to 140 deg and a 0.5 Hz sine, through the tracker and the
# simulated rig over a pseudo-terminal, in simulated time) and collects the row each case prints.
# Usage: scripts/plant_sweep_table.sh [BUILD_DIR]   (default build/; a few minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
echo "| plant (deg/kPa, ml, lag s, hysteresis deg) | settled +-1 deg | overshoot | sine 155 +- 20 deg, 0.5 Hz: RMS error |"
echo "| --- | --- | --- | --- |"
ctest --test-dir "$build" -R 'PlantSweep' -V 2>&1 | sed -n 's/^.*PlantSweep row: //p'
