# Sourced by scripts/test-sanitize.sh and scripts/fuzz.sh. ConfigureSanitizeTree [cmake args]
# configures build-sanitize/, the one instrumented tree (clang, ASan + UBSan) that holds both the
# test suite and the libFuzzer targets, so CI compiles the project with the sanitizers once.
# -O1: reports keep their line numbers and the suite stays fast enough; -gline-tables-only: file
# and line in every stack trace without the cost of full debug info. No benchmarks (timing under
# ASan means nothing), no Python module (an instrumented module cannot be loaded by the plain
# interpreter), no public-header compile check (the plain build has it; it finds nothing at run
# time). No -Werror: the plain build (scripts/test.sh) holds warnings at zero.
ConfigureSanitizeTree() {
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake -S . -B build-sanitize "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
    -DSOFTSIGHT_SANITIZE=ON -DSOFTSIGHT_FUZZ=ON -DSOFTSIGHT_BUILD_BENCHMARKS=OFF \
    -DSOFTSIGHT_BUILD_PYTHON=OFF -DSOFTSIGHT_CHECK_PUBLIC_HEADERS=OFF -DSOFTSIGHT_WERROR=OFF \
    "$@" >/dev/null
}
