# Sourced by scripts/test-sanitize.sh and scripts/fuzz.sh. ConfigureSanitizeTree [cmake args]
# configures build-sanitize/, the one instrumented tree (clang, ASan + UBSan) that holds both the
# test suite and the libFuzzer targets, so CI compiles the project with the sanitizers once.
# -O0, but -O1 for the modules whose arithmetic the tests spend their time in (core, geometry,
# track, sim, control, pipeline: tracking rendered scenes, the simulated plants):
# compiling for ASan at -O1 spent most of its time in LLVM's optimiser on code that runs once per
# test (web_server.cc: 82 s of CPU at -O1, 28 s at -O0; the whole tree 836 s -> see
# docs/measurements.md), while these modules at -O0 would make the instrumented tests slower.
# -gline-tables-only: file and line in every stack trace without the cost of full debug info. No benchmarks (timing under
# ASan means nothing), no Python module (an instrumented module cannot be loaded by the plain
# interpreter), no public-header compile check (the plain build has it; it finds nothing at run
# time). No -Werror: the plain build (scripts/test.sh) holds warnings at zero.
# The tests built instrumented: the modules that take outside input (configs, videos, CSVs, board
# answers, the stream, a web page's messages) or hold the trackers' and the session's pixel
# arithmetic (web: its C++ tests; its browser tests stay in the plain tree, src/web/CMakeLists.txt). The commands'
# end-to-end tests are not rebuilt: scripts/test-sanitize.sh runs the plain tree's against the
# instrumented program. The renderer, calibration, geometry and the live window run instrumented
# inside the program and the tests above, and plainly in scripts/test.sh.
SANITIZE_TEST_MODULES="core;config;io;control;stream;track;pipeline;firmware;web"
ConfigureSanitizeTree() {
  local generator=()
  command -v ninja >/dev/null && generator=(-G Ninja)
  cmake -S . -B build-sanitize "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O0 -gline-tables-only" \
    -DSOFTSIGHT_O1_MODULES="core;geometry;track;sim;control;pipeline" \
    -DSOFTSIGHT_SANITIZE=ON -DSOFTSIGHT_FUZZ=ON -DSOFTSIGHT_BUILD_BENCHMARKS=OFF \
    -DSOFTSIGHT_BUILD_PYTHON=OFF -DSOFTSIGHT_CHECK_PUBLIC_HEADERS=OFF -DSOFTSIGHT_WERROR=OFF \
    -DSOFTSIGHT_TEST_MODULES="$SANITIZE_TEST_MODULES" \
    "$@" >/dev/null
}
