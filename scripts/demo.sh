#!/usr/bin/env bash
# Installs dependencies, builds, and runs the main job on the built-in demo scene (README command 1):
# renders a synthetic bending actuator to a video, tracks it, writes the CSV, prints the summary.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh
build/src/app/softsight demo --out-dir demo_out "$@"
