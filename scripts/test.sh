#!/usr/bin/env bash
# Installs dependencies, builds, and runs the whole test suite (README command 2).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
WERROR=OFF
if [ "${CI:-}" = "true" ]; then WERROR=ON; fi
scripts/build.sh -DSOFTSIGHT_WERROR="$WERROR"
cd build
ctest --output-on-failure --parallel "$(nproc)" --timeout 240
