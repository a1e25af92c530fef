#!/usr/bin/env bash
# Regenerates the table "Speed where users wait" of docs/measurements.md (issue 13): every figure is printed
# beside references measured in the same run, on the same files (a bare decode loop of the file,
# one BGR -> gray pass over its frame, /bin/true for start-up), so the ratios hold on another or
# a busier machine. Prints the Markdown table to stdout; the machine's load average is printed
# with it (on a shared machine, compare ratios, not absolute times).
#   scripts/bench.sh [WORK_DIR]     (default: bench_out/, reused: rendered videos are kept)
# Then the per-frame "Speed" table of docs/measurements.md of the trackers and recordings, from the Google
# Benchmark programs (their JSON kept in WORK_DIR), each row beside the BGR -> gray pass its own
# program measured in the same run. Then the TrackingSession table: the session per frame with three
# colour markers and with three ZNCC templates, at 640x480 and 1280x720, beside the gray pass
# (issue 45; their instruction counts, steady on a busy machine: scripts/session_instructions.sh).
# Then `track` on H.264 (VGA and 1080p, a key frame every 250 frames) beside a bare decode of the
# same file: wall, CPU and peak RSS, and how long rows waited for their key-frame group's check.
# Then the real sequence mire-2 beside ViSP's vpDot2 (needs libvisp-dev; skipped with a message
# without it).
# Takes about 4 minutes on an idle 2-core machine. Needs a build (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${1:-bench_out}
mkdir -p "$WORK"
cmake --build build --target softsight softsight_speed_report softsight_benchmarks >/dev/null
S=build/src/app/softsight
CFG=examples/markers.yaml
PY=$(command -v python3)

# Four rendered 640x480 videos of 300 frames (softsight's own lossless HuffYUV recordings,
# different textures) and one FFV1 copy (older recordings).
for k in 1 2 3 4; do
  [ -f "$WORK/v$k.avi" ] || "$S" synth --scene bending --frames 300 --seed "$k" --out "$WORK/v$k.avi" -q
done
[ -f "$WORK/v1_ffv1.avi" ] || "$S" synth --scene bending --frames 300 --seed 1 --codec ffv1 \
  --out "$WORK/v1_ffv1.avi" -q
# The same four as MJPG, the usual format of a lab camera's recordings: FFmpeg decodes MJPG on
# one thread, HuffYUV on as many as there are cores.
for k in 1 2 3 4; do
  [ -f "$WORK/m$k.avi" ] || "$S" synth --scene bending --frames 300 --seed "$k" --codec mjpg \
    --out "$WORK/m$k.avi" -q
done

echo "Measured $(date -u +%Y-%m-%dT%H:%MZ) on $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| what | measured | references in the same run |"
echo "| --- | --- | --- |"

# Decoding on its own thread: track's wall time per frame against a bare decode loop.
build/src/app/softsight_speed_report "$CFG" "$WORK/v1.avi" "$WORK" | sed 's/ .avi file/ HuffYUV .avi file/'
build/src/app/softsight_speed_report "$CFG" "$WORK/v1_ffv1.avi" "$WORK" | sed 's/ .avi file/ FFV1 .avi file/'
build/src/app/softsight_speed_report "$CFG" "$WORK/m1.avi" "$WORK" | sed 's/ .avi file/ MJPG .avi file/'

"$PY" - "$S" "$CFG" "$WORK" <<'PYEOF'
import csv, os, resource, statistics, subprocess, sys, time

softsight, config, work = sys.argv[1:4]
videos = [os.path.join(work, f"v{k}.avi") for k in (1, 2, 3, 4)]

def wall(cmd):
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start

def median_ms(cmd, n=20):
    return statistics.median(wall(cmd) for _ in range(n)) * 1000

# Several inputs: --jobs 1 and --jobs 2 on the same 4 videos, alternated, median of 3 rounds,
# with the CPU time the run's processes used (every thread of every job): that over the cores is
# the least wall time any schedule could take, so wall / floor says how busy the cores were.
def wall_and_cpu(cmd):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    seconds = wall(cmd)
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return seconds, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)

cores = os.cpu_count() or 1
for label, names in (("HuffYUV", "v"), ("MJPG", "m")):
    files = [os.path.join(work, f"{names}{k}.avi") for k in (1, 2, 3, 4)]
    inputs = [a for v in files for a in ("-i", v)]
    runs = {1: [], 2: []}
    for _ in range(3):
        for n in (1, 2):
            runs[n].append(wall_and_cpu([softsight, "track", "-c", config, *inputs, "-o",
                                         os.path.join(work, f"jobs{n}") + "/", "--jobs", str(n), "-q"]))
    # The median round by wall time, with its own CPU time.
    (one, one_cpu), (two, two_cpu) = (sorted(runs[n])[1] for n in (1, 2))
    frames = 4 * 300
    print(f"| `track` of 4 {label} files (1200 frames) in one run: `--jobs 1` / `--jobs 2` | "
          f"{frames / one:.0f} / {frames / two:.0f} frames/s ({one / two:.2f}x) | CPU time of the "
          f"run {one_cpu:.2f} / {two_cpu:.2f} s: `--jobs 1` keeps {one_cpu / one:.1f} of {cores} "
          f"cores busy (decoding, FFmpeg's own threads, tracking), `--jobs 2` "
          f"{two_cpu / two:.1f}, its wall time {two / (two_cpu / cores):.2f}x the CPU floor "
          f"(CPU time / cores); each input's process starts in about the `track --help` time "
          f"below; load average {os.getloadavg()[0]:.1f} |")

# Start-up: median of 20 runs, and the shared libraries the dynamic loader initialised.
def libraries(cmd):
    run = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
                         env=dict(os.environ, LD_DEBUG="libs"))
    return sum("calling init:" in line for line in run.stderr.splitlines())
true_ms = median_ms(["/bin/true"])
for args in (["--version"], ["--help"], ["track", "--help"], ["live", "--help"]):
    cmd = [softsight, *args]
    print(f"| start-up: `softsight {' '.join(args)}` | {median_ms(cmd):.1f} ms median of 20, "
          f"{libraries(cmd)} libraries | `/bin/true` {true_ms:.1f} ms |")

# Latency over the simulated rig (board and actuator on a pseudo-terminal, frames rendered in
# lock-step): the distribution of the CSV's latency columns, beside the tracking time.
rig_csv = os.path.join(work, "rig.csv")
subprocess.run([softsight, "control", "--config", "examples/rig.yaml", "--simulate",
                "--target-deg", "120", "--duration-s", "20", "--csv", rig_csv, "-q"], check=True,
               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
with open(rig_csv) as f:
    rows = list(csv.DictReader(f))
def dist(name):
    v = sorted(float(r[name]) for r in rows if r[name])
    q = lambda p: v[min(len(v) - 1, int(p * len(v)))]
    return f"median {q(0.5):.3f}, p99 {q(0.99):.3f}, max {v[-1]:.3f} ms"
proc = statistics.median(float(r["proc_ms"]) for r in rows)
print(f"| latency over the simulated rig ({len(rows)} frames, 640x480): capture -> result / -> "
      f"serial command / -> CSV row | {dist('latency_result_ms')} / {dist('latency_command_ms')} / "
      f"{dist('latency_row_ms')} | tracking alone (proc_ms) median {proc:.3f} ms |")
PYEOF

# The trackers and recordings per frame (Google Benchmark). The colour program runs OpenCV
# single-threaded and also reports thread CPU time; the recording program reports the process's
# CPU time (FFmpeg decodes on helper threads) and runs on one core. Their console output goes to
# WORK_DIR/*.log.
echo
echo "Per frame (Google Benchmark), load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
build/src/track/softsight_colour_tracker_benchmark --benchmark_out_format=json --benchmark_out="$WORK/colour.json" >/dev/null 2>"$WORK/colour.log"
build/src/track/softsight_template_matching_benchmark --benchmark_out_format=json \
  --benchmark_filter='BM_(TrackWindowed|AcquireWholeFrame/2|SadVector/1|SadPlainScalar/1|SadAutoVectorisedLoop/1|BaselineWholeFrameMatchTemplate|GrayConversion)' \
  --benchmark_out="$WORK/template.json" >/dev/null 2>"$WORK/template.log"
build/src/pipeline/softsight_tracking_session_benchmark --benchmark_out_format=json \
  --benchmark_out="$WORK/session.json" >/dev/null 2>"$WORK/session.log"
taskset -c 0 build/src/io/softsight_frame_writer_benchmark --benchmark_out_format=json \
  --benchmark_out="$WORK/writer.json" >/dev/null 2>"$WORK/writer.log"

"$PY" - "$WORK" <<'PYEOF'
import json, os, sys

work = sys.argv[1]
def load(name):
    with open(os.path.join(work, name)) as f:
        return {b["name"]: b for b in json.load(f)["benchmarks"]}
colour, templ, writer = load("colour.json"), load("template.json"), load("writer.json")

def ms(b, key="real_time"):  # A benchmark's time in ms, whatever its unit.
    scale = {"ns": 1e-6, "us": 1e-3, "ms": 1.0, "s": 1e3}[b["time_unit"]]
    return b[key] * scale

print("| what | 640x480 | 1280x720 | reference in the same run |")
print("| --- | --- | --- | --- |")
g = {s: colour[f"BM_GrayReference/{s}"] for s in ("640/480", "1280/720")}
gray_ref = (f"gray pass {g['640/480']['ms_per_frame']:.3f} / {g['1280/720']['ms_per_frame']:.3f} ms "
            f"(thread CPU {g['640/480']['cpu_ms_per_frame']:.3f} / {g['1280/720']['cpu_ms_per_frame']:.3f} ms)")
def colour_row(what, name):
    a, b = colour[f"{name}/640/480"], colour[f"{name}/1280/720"]
    cell = lambda r: (f"{r['ms_per_frame']:.3f} ms ({r['x_gray']:.2f}x gray), thread CPU "
                      f"{r['cpu_ms_per_frame']:.3f} ms ({r['cpu_x_gray']:.2f}x)")
    print(f"| {what} | {cell(a)} | {cell(b)} | {gray_ref} |")
colour_row("colour (verified, soft centroid), ROI tracking, 3 markers", "BM_ColourRoi3")
colour_row("colour, whole frame every frame (`window: 0`)", "BM_ColourFullFrame3")
colour_row("colour, re-acquiring every frame", "BM_ColourReacquire3")
t, r = colour["BM_AutoColourBenchTrack3"], colour["BM_AutoColourBenchReacquire3"]
print(f"| colour, `auto_colour` on the bench with look-alikes: tracking / re-acquiring every frame "
      f"| median {t['median_ms']:.3f} / {r['median_ms']:.3f} ms, p99 {t['p99_ms']:.3f} / {r['p99_ms']:.3f} ms "
      f"({t['x_gray']:.1f}x / {r['x_gray']:.1f}x gray); thread CPU median {t['cpu_median_ms']:.3f} / "
      f"{r['cpu_median_ms']:.3f} ms, p99 {t['cpu_p99_ms']:.3f} / {r['cpu_p99_ms']:.3f} ms | | "
      f"gray pass of the same frames {t['gray_median_ms']:.3f} ms |")

tg = ms(templ["BM_GrayConversion"])
tref = f"gray pass {tg:.3f} ms"
def methods(colour_arg):
    return [ms(templ[f"BM_TrackWindowed/{m}/{colour_arg}"]) for m in (0, 1, 2)]
for arg, label in ((0, "gray"), (1, "colour")):
    sad, ssd, zncc = methods(arg)
    print(f"| template, windowed tracking, {label}, 3 markers: SAD / SSD / ZNCC | {sad:.3f} / {ssd:.3f} / "
          f"{zncc:.3f} ms ({sad / tg:.1f}x / {ssd / tg:.1f}x / {zncc / tg:.1f}x gray) | | {tref} |")
zg, zc = ms(templ["BM_AcquireWholeFrame/2/0"]), ms(templ["BM_AcquireWholeFrame/2/1"])
print(f"| template, full-frame acquisition (pyramid), ZNCC gray / colour, 3 markers | {zg:.2f} / {zc:.2f} ms "
      f"({zg / tg:.0f}x / {zc / tg:.0f}x gray) | | {tref} |")
kernel, scalar, auto = (templ[n]["real_time"] for n in ("BM_SadVector/1", "BM_SadPlainScalar/1",
                                                         "BM_SadAutoVectorisedLoop/1"))
print(f"| SAD kernel (64x64 search, 32x32 template) vs a plain scalar loop / the loop as GCC "
      f"auto-vectorises it at -O3 | {kernel:.1f} us vs {scalar:.0f} us ({scalar / kernel:.1f}x) / "
      f"{auto:.1f} us ({auto / kernel:.1f}x) | | {tref} |")
cc, sq = ms(templ["BM_BaselineWholeFrameMatchTemplate/1"]), ms(templ["BM_BaselineWholeFrameMatchTemplate/0"])
gray_sad, gray_ssd, gray_zncc = methods(0)
print(f"| baseline: `cv::matchTemplate` on the full frame per marker, every frame: CCOEFF_NORMED / SQDIFF; "
      f"windowed tracking against it | {cc:.1f} / {sq:.1f} ms; ZNCC {cc / gray_zncc:.0f}x, SSD "
      f"{sq / gray_ssd:.0f}x faster | | {tref} |")

wg = ms(writer["BM_GrayReference"])
def fps(kind, codec, noise):
    return writer[f"BM_{kind}/codec:{codec}/noise:{noise}/process_time"]["items_per_second"]
for noise, label in ((0, "clean scene"), (4, "sensor noise sigma 4")):
    he, hd = fps("Encode", 1, noise), fps("Decode", 1, noise)
    fe, fd = fps("Encode", 0, noise), fps("Decode", 0, noise)
    print(f"| lossless recording (HuffYUV) at 640x480, {label}: encode / decode, process CPU time "
          f"on one core | {he:.0f} / {hd:.0f} fps (FFV1 {fe:.0f} / {fd:.0f}: {he / fe:.1f}x / {hd / fd:.1f}x) "
          f"| | gray pass {wg:.3f} ms |")
PYEOF

# What TrackingSession costs beside a gray pass (issue 45: at most one at 640x480, with three
# colour markers and with three ZNCC templates) and beyond its trackers (issue 26, item 7): thread
# CPU time per frame (OpenCV on one thread), each row beside the gray pass the session program
# measured in the same run; wall time in brackets. Instruction counts of the same rows, which do
# not move with the machine's load: scripts/session_instructions.sh.
echo
echo "TrackingSession per frame (thread CPU time, Google Benchmark), load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
"$PY" - "$WORK" <<'PYEOF'
import json, os, sys
with open(os.path.join(sys.argv[1], "session.json")) as f:
    b = {x["name"]: x for x in json.load(f)["benchmarks"]}
sizes = ("640/480", "1280/720")
cpu = lambda name, s: b[f"{name}/{s}"]["cpu_ms_per_frame"]
wall = lambda name, s: b[f"{name}/{s}"]["ms_per_frame"]
print("| what | 640x480 | 1280x720 | target |")
print("| --- | --- | --- | --- |")
def cell(name, s):
    return (f"{cpu(name, s):.3f} ms ({cpu(name, s) / cpu('BM_GrayReference', s):.2f}x gray; wall "
            f"{wall(name, s) / wall('BM_GrayReference', s):.2f}x)")
def row(what, name, target=""):
    print(f"| {what} | {' | '.join(cell(name, s) for s in sizes)} | {target} |")
row("BGR -> gray pass (reference)", "BM_GrayReference")
row("the three colour trackers alone", "BM_Trackers3")
row("`TrackingSession::process`, 3 colour markers", "BM_Session3", "<= 1.0x gray at 640x480")
row("the three ZNCC template trackers alone", "BM_Trackers3Zncc")
row("`TrackingSession::process`, 3 ZNCC templates", "BM_Session3Zncc", "<= 1.0x gray at 640x480")
row("of it: `FrameChangeDetector::observe`", "BM_FrameChange")
for label, session, trackers in (("colour", "BM_Session3", "BM_Trackers3"),
                                 ("ZNCC", "BM_Session3Zncc", "BM_Trackers3Zncc")):
    over = " | ".join(f"{cpu(session, s) - cpu(trackers, s):.3f} ms "
                      f"({(cpu(session, s) - cpu(trackers, s)) / cpu(trackers, s):.2f}x the trackers)"
                      for s in sizes)
    print(f"| the session's own checks (whole - trackers), {label} | {over} | <= the trackers' time |")
PYEOF

# `track` on H.264 (issue 45: <= 1.2x the bare decode of the same file and <= 2x its memory, rows
# not held back by more than one key-frame group): a VGA and a 1080p rendering re-encoded as H.264
# with a key frame every 250 frames (libx264's default; softsight_h264_clip), `softsight track`
# (CSV only) beside a bare decode loop of the file (OpenCV's FFmpeg reader, nothing else) and the
# file's frame source alone (its own decode, io/libav_video_reader.h, with the decoder's damage
# marks, and the key-frame checks), each in a process of its own under /usr/bin/time (wall, CPU,
# peak RSS), alternated, median of 5 rounds; how long rows waited for their group's check: the
# CSV's latency_row_ms (a file's frame is stamped as it is tracked). (Until 2026-12-07 the
# reference was the frame source, which then ran a second decode for the damage marks, and the
# ratios were 1.07-1.25x; against the bare decode they were 1.50x.)
cmake --build build --target softsight_h264_clip >/dev/null
for size in 640x480 1920x1080; do
  [ -f "$WORK/h264_$size.mp4" ] && continue
  "$S" synth --scene bending --frames 300 --seed 1 --size "$size" --out "$WORK/h264_$size.avi" -q
  build/src/app/softsight_h264_clip "$WORK/h264_$size.avi" "$WORK/h264_$size.mp4" 250 >/dev/null
  rm -f "$WORK/h264_$size.avi"
done
echo
echo "\`track\` on H.264, load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
"$PY" - "$S" "$CFG" "$WORK" <<'PYEOF'
import csv, os, statistics, subprocess, sys, tempfile
softsight, config, work = sys.argv[1:4]
def timed(cmd):
    with tempfile.NamedTemporaryFile("r") as t:
        subprocess.run(["/usr/bin/time", "-f", "%e %U %S %M", "-o", t.name, *cmd], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        wall, user, system, rss_kb = t.read().split()[-4:]
    return float(wall), float(user) + float(system), int(rss_kb) / 1024
print("| what | `track` | bare decode of the same file, in the same run | the file's frame source alone "
      "(decode + damage checks) | target |")
print("| --- | --- | --- | --- | --- |")
for size in ("640x480", "1920x1080"):
    clip = os.path.join(work, f"h264_{size}.mp4")
    out = os.path.join(work, f"h264_{size}.csv")
    runs = {"track": [], "decode": [], "source": []}
    for _ in range(5):
        runs["decode"].append(timed(["build/src/app/softsight_speed_report", "--decode", clip]))
        runs["source"].append(timed(["build/src/app/softsight_speed_report", "--source", clip]))
        runs["track"].append(timed([softsight, "track", "-c", config, "-i", clip, "-o", out, "-q"]))
    med = {k: [statistics.median(r[i] for r in v) for i in range(3)] for k, v in runs.items()}
    (tw, tc, tm), (dw, dc, dm), (sw, sc, sm) = med["track"], med["decode"], med["source"]
    with open(out) as f:
        waits = sorted(float(r["latency_row_ms"]) for r in csv.DictReader(f) if r["latency_row_ms"])
    print(f"| `track` of a {size} H.264 file (300 frames, a key frame every 250), CSV only: wall / "
          f"CPU / peak RSS | {tw:.2f} s ({tw / dw:.2f}x) / {tc:.2f} s ({tc / dc:.2f}x) / {tm:.0f} MB "
          f"({tm / dm:.2f}x); rows waited median {waits[len(waits) // 2]:.0f} ms, max {waits[-1]:.0f} ms "
          f"| {dw:.2f} s / {dc:.2f} s / {dm:.0f} MB | {sw:.2f} s ({sw / dw:.2f}x) / {sc:.2f} s "
          f"({sc / dc:.2f}x) / {sm:.0f} MB | <= 1.2x wall, <= 2x memory |")
PYEOF

# The real-sequence case (issue 45: the session <= 3x ViSP's vpDot2 per frame, the same dots
# found): ViSP's mire-2 (tests/real/mire2, 501 real 384x288 frames, 5 white dots), its colour and
# ZNCC configs, both trackers on the same preloaded frames in one process and thread, each
# figure beside vpDot2's from the same run (src/app/vpdot2_compare.cc). ViSP is needed by this
# row only (Debian: libvisp-dev; SOFTSIGHT_BENCH_INSTALL=1 installs it with apt-get).
echo
echo "The real sequence beside vpDot2, load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
if ! dpkg -s libvisp-dev >/dev/null 2>&1 && [ "${SOFTSIGHT_BENCH_INSTALL:-0}" = 1 ]; then
  apt-get install -y libvisp-dev >/dev/null && cmake -S . -B build >/dev/null
fi
if cmake --build build --target softsight_vpdot2_compare >/dev/null 2>&1; then
  echo "| what | softsight | vpDot2 in the same run |"
  echo "| --- | --- | --- |"
  for cfg in colour zncc; do
    (cd tests/real/mire2 && "$OLDPWD/build/src/app/softsight_vpdot2_compare" "$cfg.yaml" \
      'frames/image.%04d.png' 5)
  done
else
  echo "(skipped: ViSP is not installed, so softsight_vpdot2_compare is not built; install"
  echo "libvisp-dev, or run with SOFTSIGHT_BENCH_INSTALL=1, and reconfigure)"
fi

# The stream (--publish, issue 28): capture-to-subscriber latency beside the CSV row's, and the
# run's own time per frame with 0, 1 and 10 subscribers beside a run without --publish.
echo
echo "The stream (--publish), load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
build/src/stream/softsight_publish_benchmark --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_out_format=json \
  --benchmark_out="$WORK/publish.json" >/dev/null 2>"$WORK/publish.log"
"$PY" - "$WORK" <<'PYEOF'
import json, os, sys
with open(os.path.join(sys.argv[1], "publish.json")) as f:
    b = {x["name"]: x for x in json.load(f)["benchmarks"]}
# Each figure: the median over 5 repetitions.
print("| what | median | p99 | reference in the same run |")
print("| --- | --- | --- | --- |")
for arg, label in ((0, "ipc://"), (1, "tcp://127.0.0.1")):
    r = b[f"BM_CaptureToSubscriber/{arg}/iterations:3000/real_time_median"]
    print(f"| capture to a subscriber's receive, {label} | {r['subscriber_ms_median']:.3f} ms | "
          f"{r['subscriber_ms_p99']:.3f} ms | CSV row {r['csv_row_ms_median']:.3f} / {r['csv_row_ms_p99']:.3f} ms; "
          f"subscriber - row medians {r['subscriber_minus_row_ms_median']:.3f} ms (target <= 1 ms) |")
base = b["BM_RunCost/-1/iterations:600/real_time_median"]
for n in (0, 1, 10):
    r = b[f"BM_RunCost/{n}/iterations:600/real_time_median"]
    drops = f", {int(r['dropped'])} of {int(r['sent'])} messages dropped" if r.get("dropped") else ""
    print(f"| the run's thread per frame (session + CSV + stream, 640x480, 3 markers), {n} subscribers{drops} | "
          f"wall {r['real_time']:.3f} ms, CPU {r['cpu_time']:.3f} ms | | without --publish: wall "
          f"{base['real_time']:.3f} ms, CPU {base['cpu_time']:.3f} ms |")
PYEOF

# The per-frame hook (--hook, issue 47): what HookSink::consume costs the run's thread per frame.
echo
echo "The per-frame hook (--hook), load average $(cut -d' ' -f1-3 /proc/loadavg):"
echo
build/src/app/softsight_hook_benchmark --benchmark_repetitions=5 \
  --benchmark_report_aggregates_only=true --benchmark_out_format=json \
  --benchmark_out="$WORK/hook.json" >/dev/null 2>"$WORK/hook.log"
"$PY" - "$WORK" <<'PYEOF'
import json, os, sys
with open(os.path.join(sys.argv[1], "hook.json")) as f:
    b = {x["name"]: x for x in json.load(f)["benchmarks"]}
print("| hook | per frame (median of 5) | CPU |")
print("| --- | --- | --- |")
for name, label in (("BM_CppHookInTheRun", "trivial C++ hook, in the run (a file)"),
                    ("BM_CppHookOnItsThread/real_time", "trivial C++ hook, on its own thread (a camera: VGA frame copied, handed over, waited for)"),
                    ("BM_PythonEmptyHook", "empty Python hook file (`--hook`), in the run"),
                    ("BM_PythonMarkerHook", "Python hook summing the markers' x, in the run")):
    r = b[name + "_median"]
    unit = {"ns": 1e-6, "us": 1e-3, "ms": 1.0}[r["time_unit"]]
    print(f"| {label} | {r['real_time'] * unit:.4f} ms | {r['cpu_time'] * unit:.4f} ms |")
PYEOF
