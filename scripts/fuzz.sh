#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, -DSOFTSIGHT_FUZZ=ON) in build-fuzz/ and runs
# each on its committed seed corpus (fuzz/corpus/<target>/). New inputs go to a scratch folder,
# so the corpus in the repository only changes by hand. A crash leaves its input in
# build-fuzz/crashes/ and fails the script.
#   scripts/fuzz.sh                          # CI: a bounded run, 20000 inputs each, seed 1
#   scripts/fuzz.sh -max_total_time=600      # a longer run: these libFuzzer flags replace the bound
#   scripts/fuzz.sh -runs=1000000 config     # flags, then target names (config sequence_pattern csv protocol)
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/sanitizer/env.sh
FLAGS=()
TARGETS=()
for arg in "$@"; do
  if [[ "$arg" == -* ]]; then FLAGS+=("$arg"); else TARGETS+=("$arg"); fi
done
[ ${#FLAGS[@]} -eq 0 ] && FLAGS=(-runs=20000 -seed=1)
[ ${#TARGETS[@]} -eq 0 ] && TARGETS=(config sequence_pattern csv protocol)
GENERATOR=()
command -v ninja >/dev/null && GENERATOR=(-G Ninja)
cmake -S . -B build-fuzz "${GENERATOR[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DCMAKE_CXX_COMPILER=clang++ -DSOFTSIGHT_FUZZ=ON \
  -DSOFTSIGHT_BUILD_TESTS=OFF -DSOFTSIGHT_BUILD_BENCHMARKS=OFF
BUILD_TARGETS=()
for t in "${TARGETS[@]}"; do BUILD_TARGETS+=("softsight_${t}_fuzzer"); done
cmake --build build-fuzz --parallel "$(nproc)" --target "${BUILD_TARGETS[@]}"
mkdir -p build-fuzz/crashes
for t in "${TARGETS[@]}"; do
  scratch="$(mktemp -d)"
  echo "fuzz: $t (${FLAGS[*]})"
  # -timeout: an input that takes seconds is a hang, and fails like a crash.
  "build-fuzz/fuzz/softsight_${t}_fuzzer" "${FLAGS[@]}" -max_len=4096 -timeout=10 -rss_limit_mb=2048 \
    -artifact_prefix="build-fuzz/crashes/${t}-" -print_final_stats=1 "$scratch" "fuzz/corpus/$t" \
    2> "build-fuzz/$t.log" || { tail -n 60 "build-fuzz/$t.log"; rm -rf "$scratch"; exit 1; }
  grep -E "^stat::number_of_executed_units|^Done" "build-fuzz/$t.log" || true
  rm -rf "$scratch"
done
echo "fuzz: ${#TARGETS[@]} targets, no crash"
