#!/usr/bin/env bash
# Makes docs/images/live-window.png, the live window as docs/live.md shows it: `softsight live` on
# the demo's rendered video under a virtual display (Xvfb), driven with xdotool as a person would
# (play, record a second and a half, make the tip active and drag a box on background, which
# loses it, pause, zoom in with + at the pointer), then Xvfb's own framebuffer (-fbdir, an XWD
# file) cropped to the window and written as PNG. No screenshot tool needed. The keys are timed
# with sleeps (this makes a picture; the tests wait for the window's stdout lines instead).
# Usage: scripts/live-screenshot.sh [BUILD_DIR]   (default build; needs Xvfb and xdotool)
set -euo pipefail
cd "$(dirname "$0")/.."
BIN="$(realpath "${1:-build}")/src/app/softsight"
OUT=docs/images/live-window.png
work=$(mktemp -d)
pids=()
cleanup() {
  for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
  rm -rf "$work"
}
trap cleanup EXIT

"$BIN" demo --out-dir "$work/demo" --frames 240 --quiet
video=$(ls "$work"/demo/*.avi | head -1)
config=$(ls "$work"/demo/*.yaml | head -1)

# A display number Xvfb finds free (other users' displays are left alone).
Xvfb -displayfd 3 -screen 0 1280x900x24 -fbdir "$work" -nolisten tcp 3>"$work/display" &
pids+=($!)
for _ in $(seq 50); do [ -s "$work/display" ] && break; sleep 0.1; done
export DISPLAY=":$(cat "$work/display")"
(cd "$work" && exec "$BIN" live --input "$video" --config "$config" --no-trackbars \
   --record-prefix "$work/live" > "$work/live.log" 2>&1) &
pids+=($!)
timeout 60 xdotool search --sync --onlyvisible --name "softsight live" windowfocus --sync >/dev/null
key() { xdotool key "$@"; sleep 0.4; }
sleep 2
key r; sleep 1.5; key r                 # a recording: green along the timeline's top
sleep 1
key 3                                    # the tip (green) is active
xdotool mousemove 5 5 mousedown 1 mousemove 60 60 mouseup 1; sleep 0.5   # a box on background: refused
sleep 1.5
key space                                # paused
win=$(xdotool search --onlyvisible --name "softsight live" | head -1)
eval "$(xdotool getwindowgeometry --shell "$win")"
X=0; Y=0  # Without a window manager the window is at the screen corner, undecorated.
# Near the middle marker (blue) at this point of the demo: the upper middle of the window.
bx=$((WIDTH / 2)); by=$((HEIGHT / 3))
xdotool mousemove $bx $by
for _ in 1 2 3 4; do xdotool key plus; sleep 0.3; done
sleep 1.5
python3 - "$work/Xvfb_screen0" "$OUT" "$X" "$Y" "$WIDTH" "$HEIGHT" <<'PY'
import struct, sys, zlib
src, out, x0, y0, w, h = sys.argv[1], sys.argv[2], *map(int, sys.argv[3:])
data = open(src, 'rb').read()
header_size = struct.unpack('>I', data[0:4])[0]
fields = struct.unpack('>25I', data[0:100])
width, height, bpp, bytes_per_line, ncolors = fields[4], fields[5], fields[11], fields[12], fields[19]
pixels = header_size + ncolors * 12
assert bpp == 32, bpp
rows = []
for y in range(y0, y0 + h):
    line = data[pixels + y * bytes_per_line + 4 * x0: pixels + y * bytes_per_line + 4 * (x0 + w)]
    rgb = bytearray(3 * w)
    rgb[0::3], rgb[1::3], rgb[2::3] = line[2::4], line[1::4], line[0::4]  # BGRX -> RGB
    rows.append(b'\0' + bytes(rgb))
def chunk(kind, body):
    return struct.pack('>I', len(body)) + kind + body + struct.pack('>I', zlib.crc32(kind + body) & 0xffffffff)
png = b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0))
png += chunk(b'IDAT', zlib.compress(b''.join(rows), 9)) + chunk(b'IEND', b'')
open(out, 'wb').write(png)
print(f"{out}: {w}x{h}, {len(png) // 1024} KB")
PY
xdotool key q || true
