#!/usr/bin/env bash
# The whole test suite again, built with AddressSanitizer + UBSan (-DSOFTSIGHT_SANITIZE=ON) in
# build-sanitize/ (README's second, optional test command; CI runs it after scripts/test.sh).
# Any memory error, leak (system libraries in scripts/sanitizer/lsan.supp aside) or undefined
# behaviour fails the test that caused it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/sanitizer/env.sh
GENERATOR=()
command -v ninja >/dev/null && GENERATOR=(-G Ninja)
# -O1: sanitizer reports keep their line numbers, and the suite stays fast enough. No -Werror:
# GCC's flow warnings (-Wmaybe-uninitialized) misfire on sanitizer-instrumented code; the plain
# build (scripts/test.sh) is the one that holds warnings at zero.
cmake -S . -B build-sanitize "${GENERATOR[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DSOFTSIGHT_SANITIZE=ON \
  -DSOFTSIGHT_BUILD_BENCHMARKS=OFF -DSOFTSIGHT_WERROR=OFF "$@"
cmake --build build-sanitize --parallel "$(nproc)"
cd build-sanitize
ctest --output-on-failure --parallel "$(nproc)" --timeout 480
