#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, -DSOFTSIGHT_FUZZ=ON) in build-sanitize/, the
# tree scripts/test-sanitize.sh builds the instrumented suite in (after it, nothing is left to
# compile), and runs each on its committed seed corpus (fuzz/corpus/<target>/). New inputs go to
# a scratch folder, so the corpus in the repository only changes by hand. A crash leaves its
# input in build-sanitize/fuzz-out/crashes/ and fails the script.
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
source scripts/sanitizer/configure.sh
ConfigureSanitizeTree
BUILD_TARGETS=()
for t in "${TARGETS[@]}"; do BUILD_TARGETS+=("softsight_${t}_fuzzer"); done
cmake --build build-sanitize --parallel "$(nproc)" --target "${BUILD_TARGETS[@]}"
OUT=build-sanitize/fuzz-out
mkdir -p "$OUT/crashes"
# One scratch folder for the run: new corpus inputs (scratch/corpus) and the harnesses' input files
# (scratch/files: libFuzzer ends with _Exit, so the harness cannot remove them itself). Removed
# however the script ends.
scratch="$(mktemp -d -t softsight_fuzz_run.XXXXXX)"
trap 'rm -rf "$scratch"' EXIT
export SOFTSIGHT_FUZZ_SCRATCH="$scratch/files"
for t in "${TARGETS[@]}"; do
  rm -rf "$scratch/corpus" && mkdir -p "$scratch/corpus"
  echo "fuzz: $t (${FLAGS[*]})"
  # -timeout: an input that takes seconds is a hang, and fails like a crash.
  "build-sanitize/fuzz/softsight_${t}_fuzzer" "${FLAGS[@]}" -max_len=4096 -timeout=10 \
    -rss_limit_mb=2048 -artifact_prefix="$OUT/crashes/${t}-" -print_final_stats=1 "$scratch/corpus" \
    "fuzz/corpus/$t" 2> "$OUT/$t.log" || { tail -n 60 "$OUT/$t.log"; exit 1; }
  grep -E "^stat::number_of_executed_units|^Done" "$OUT/$t.log" || true
done
echo "fuzz: ${#TARGETS[@]} targets, no crash"
