#!/bin/bash
# Renders the physically based test scenes into tests/pbr/<scene>/ (tests/pbr/README.md).
#
#   bash scripts/pbr/render.sh                 # every scene
#   bash scripts/pbr/render.sh finger wedge    # some
#   POST_ONLY=1 bash scripts/pbr/render.sh     # redo noise, codec, truth and configs from the
#                                              # frames already rendered in $WORK
#   RENDER_ONLY=1 bash scripts/pbr/render.sh   # only the Blender part
#
# Blender (3.4, Cycles on the CPU) is a development dependency only: CI does not render, the tests
# read the committed results. Step 1 (Blender, scripts/pbr/scene.py) renders the frames and the
# exact truth into $WORK/<scene>/; step 2 (/usr/bin/python3 with OpenCV, scripts/pbr/post.py) adds
# sensor noise, encodes MJPG or H.264, writes truth.csv, scene.json and the configs a user would
# make (pick.yaml by `softsight pick --at` the frame-0 centres, zncc.yaml with a box per marker).
# Each Blender process uses one thread at low priority (a shared machine); JOBS run at once.
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/../.." && pwd)
WORK=${WORK:-/tmp/softsight-pbr}
JOBS=${JOBS:-2}
SAMPLES=${SAMPLES:-12}
SOFTSIGHT=${SOFTSIGHT:-$ROOT/build/src/app/softsight}
PY=${PYTHON:-/usr/bin/python3}
ALL=(bench side distractors finger fastblur wedge whitedots pale stickers hard wedgehard blackdots mat hd
     darkdomes wood960)
if [ $# -gt 0 ]; then SCENES=("$@"); else SCENES=("${ALL[@]}"); fi
mkdir -p "$WORK"

if [ -z "${POST_ONLY:-}" ]; then
  printf '%s\n' "${SCENES[@]}" | xargs -P "$JOBS" -I{} sh -c '
    rm -rf "$2/{}"
    nice -n 10 blender -b --factory-startup -P "$1/scripts/pbr/scene.py" -- \
      --scene {} --out "$2/{}" --threads 1 --samples "$3" > "$2/{}.log" 2>&1 \
      || { echo "render of {} failed: see $2/{}.log" >&2; exit 255; }
    grep PBR_TIMING "$2/{}.log"' sh "$ROOT" "$WORK" "$SAMPLES"
fi
[ -n "${RENDER_ONLY:-}" ] && exit 0
for s in "${SCENES[@]}"; do
  "$PY" "$ROOT/scripts/pbr/post.py" --raw "$WORK/$s" --out "$ROOT/tests/pbr/$s" --softsight "$SOFTSIGHT"
done
