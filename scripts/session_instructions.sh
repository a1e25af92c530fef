#!/usr/bin/env bash
# Instructions per frame of TrackingSession::process and its parts beside one BGR -> gray pass
# (cv::cvtColor COLOR_BGR2GRAY) of the same frames, counted by valgrind's callgrind: unlike
# times, the counts are the same from run to run and do not depend on what else the machine
# runs, so they show a change of a few percent on a shared machine (issue 45). They do not show
# what a frame costs in memory traffic or stalls: scripts/bench.sh prints the times.
# Each row runs build/src/pipeline/softsight_tracking_session_benchmark under callgrind,
# counting only its timed frames (the function TimedFrame: no rendering, no warm-up) and
# dividing by how often TimedFrame was called.
#   scripts/session_instructions.sh [WIDTH HEIGHT]     (default 640 480; about 5 minutes)
# PROGRAM=<a copy of the benchmark built from another commit> counts that one instead (before and
# after a change).
set -euo pipefail
cd "$(dirname "$0")/.."
WIDTH=${1:-640}
HEIGHT=${2:-480}
command -v valgrind >/dev/null || { echo "valgrind is not installed" >&2; exit 1; }
if [ -z "${PROGRAM:-}" ]; then
  cmake --build build --target softsight_tracking_session_benchmark >/dev/null
  PROGRAM=build/src/pipeline/softsight_tracking_session_benchmark
fi
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT

# Prints "<instructions> <calls>" of the timed frames of benchmark $1 at the chosen size.
count() {
  local out="$WORK/$1.out"
  # A second of the benchmark's own timing under callgrind: at least ~60 frames of the session,
  # every frame of the forth-and-back sweep.
  valgrind --tool=callgrind --collect-atstart=no --toggle-collect='*TimedFrame*' \
    --callgrind-out-file="$out" "$PROGRAM" \
    --benchmark_filter="^$1/$WIDTH/$HEIGHT\$" --benchmark_min_time=1 >/dev/null 2>&1
  # The caller tree lists each function's callers above it with the count of their calls:
  # "<Ir> (..)  < caller (Nx)" lines, then "<Ir> (..)  *  function". TimedFrame's own callers'
  # lines are the ones just above its "*" line.
  callgrind_annotate --inclusive=yes --tree=caller "$out" |
    awk '/  < / { match($0, /\(([0-9,]+)x\)/); n = substr($0, RSTART + 1, RLENGTH - 3)
                  gsub(",", "", n); pending += n; next }
         /  \*  / && /TimedFrame/ { gsub(",", "", $1); ir += $1; calls += pending }
         { pending = 0 }
         END { print ir, calls }'
}

read -r gray_ir gray_calls < <(count BM_GrayReference)
gray=$((gray_ir / gray_calls))
echo "Instructions per frame at ${WIDTH}x${HEIGHT} (callgrind, $(date -u +%Y-%m-%dT%H:%MZ)):"
echo
echo "| what | instructions per frame | x the gray pass |"
echo "| --- | --- | --- |"
echo "| BGR -> gray pass (reference, $gray_calls frames) | $gray | 1.00x |"
for row in "BM_Trackers3:the three colour trackers alone" \
           "BM_Session3:\`TrackingSession::process\`, 3 colour markers" \
           "BM_Trackers3Zncc:the three ZNCC template trackers alone" \
           "BM_Session3Zncc:\`TrackingSession::process\`, 3 ZNCC templates" \
           "BM_FrameChange:\`FrameChangeDetector::observe\` alone"; do
  name=${row%%:*}
  read -r ir calls < <(count "$name")
  per_frame=$((ir / calls))
  awk -v what="${row#*:}" -v n="$per_frame" -v g="$gray" -v c="$calls" \
    'BEGIN { printf "| %s (%d frames) | %d | %.2fx |\n", what, c, n, n / g }'
done
