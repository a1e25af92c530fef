#!/usr/bin/env bash
# The suite again with AddressSanitizer + UBSan (clang, -O0/-O1: scripts/sanitizer/configure.sh;
# README's second, optional test command; CI runs it after scripts/test.sh). Any memory error,
# leak (system libraries in scripts/sanitizer/lsan.supp aside) or undefined behaviour fails the
# test that caused it.
# One instrumented tree, build-sanitize/, holds the program, the fuzz targets (scripts/fuzz.sh)
# and the tests of the modules that take outside input (scripts/sanitizer/configure.sh lists
# them). Two runs:
#   1. those modules' tests, instrumented;
#   2. the plain tree's end-to-end tests of every command (ctest labels app and app_stereo:
#      hostile configs, videos, CSVs, boards over a pseudo-terminal, signals) against the
#      instrumented program,
#      so the commands run instrumented without compiling their tests a second time (they run the
#      program; their own code is the harness). Needs the plain tree: built first if absent.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/sanitizer/env.sh
source scripts/sanitizer/configure.sh
ConfigureSanitizeTree "$@"
cmake --build build-sanitize --parallel "$(nproc)"
if [ ! -x build/src/app/softsight_app_test ]; then scripts/build.sh; fi

# Left to the plain suite: the same code on more frames, more parameters or more commands, run
# here by shorter tests (a parameterised test's name goes on with "  # GetParam() = ..."):
#  - the association scenes (tens to hundreds of frames of rendered footage each, 5-110 s under
#    ASan; the session's association code runs here in the pipeline module's other tests and in
#    every end-to-end `track` run);
#  - the accuracy and equivalence sweeps of the trackers (the soft centroid against the textbook's
#    on hundreds of positions, the HSV kernel on every colour, windowed against whole-frame
#    search) whose code the trackers' other tests run;
#  - the identification runs on simulated plants but the shipped plant's, and the ten-plant sweep
#    of `identify` followed by `control` (10-15 s each under ASan);
#  - of the end-to-end tests, those that measure how well a command tracks (init, pick, evaluate,
#    synth, track-many's jobs, the camera seam, one pipeline for three commands, two cameras);
#    every refusal, hostile input, board and signal test runs against the instrumented program.
# (GoogleTest filter patterns, ':' between them; every test executable leaves them out:
# src/core/test_main.cc.)
LONG='AssociationScenes.*'
LONG+=':ColourVerification.SoftCentroidAccuracyAgainstBinaryAndTextbook'
LONG+=':ColourKernels.VectorHsvTestIsOpenCvsForEveryColour'
LONG+=':TemplateTrackerTest.WindowedSearchEqualsFullFrameSearch'
LONG+=':ColourTrackerScene.WindowedEqualsWholeFrameAndCoarseEqualsFullResolution'
for plant in big_laggy big_stiff mid stiff_fast stiff_slow weak_fast weak_slow fast_tube shipped_tube; do
  LONG+=":Identify/Plants.*/$plant"
done
LONG+=':TenPlants/PlantSweep.*'
for suite in TrackMany InitCommand InitSweep PickCommand OnePipeline EvaluateTest EvaluateVideo \
             SynthCommandTest TrackCamera; do
  LONG+=":$suite.*"
done
LONG+=':TrackStereoCommandTest.MarkersAndAngles*:TrackStereoCommandTest.WithTheRimFit*'
LONG+=':TrackStereoCommandTest.WithoutTheOffset*:TrackStereoCommandTest.MarkersSwapped*'
LONG+=':CalibrateStereoCommandTest.TwoFolders*'
for suite in TrackStereoSideBySideTest TrackStereoCamerasTest TrackStereoChainTest \
             Offsets/TrackStereoOffsetTest; do
  LONG+=":$suite.*"
done
export SOFTSIGHT_TEST_EXCLUDE="$LONG"
start=$SECONDS
(cd build-sanitize && ctest --output-on-failure --parallel "$(nproc)" --timeout 480)
echo "sanitize: instrumented tests done in $((SECONDS - start)) s"
start=$SECONDS
(cd build && SOFTSIGHT_BINARY="$PWD/../build-sanitize/src/app/softsight" \
   ctest --output-on-failure --parallel "$(nproc)" --timeout 480 -L '^app(_stereo)?$')
echo "sanitize: end-to-end tests against the instrumented program done in $((SECONDS - start)) s"
