#!/usr/bin/env bash
# Regenerates the README's table "Speed where users wait" (issue 13): every figure is printed
# beside references measured in the same run, on the same files (a bare decode loop of the file,
# one BGR -> gray pass over its frame, /bin/true for start-up), so the ratios hold on another or
# a busier machine. Prints the Markdown table to stdout; the machine's load average is printed
# with it (on a shared machine, compare ratios, not absolute times).
#   scripts/bench.sh [WORK_DIR]     (default: bench_out/, reused: rendered videos are kept)
# Takes about 2 minutes on an idle 2-core machine. Needs a build (scripts/build.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
WORK=${1:-bench_out}
mkdir -p "$WORK"
cmake --build build --target softsight softsight_speed_report >/dev/null
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

echo "Measured $(date -u +%Y-%m-%dT%H:%MZ) on $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| what | measured | references in the same run |"
echo "| --- | --- | --- |"

# Decoding on its own thread: track's wall time per frame against a bare decode loop.
build/src/app/softsight_speed_report "$CFG" "$WORK/v1.avi" "$WORK"
build/src/app/softsight_speed_report "$CFG" "$WORK/v1_ffv1.avi" "$WORK"

"$PY" - "$S" "$CFG" "$WORK" <<'PYEOF'
import csv, os, statistics, subprocess, sys, time

softsight, config, work = sys.argv[1:4]
videos = [os.path.join(work, f"v{k}.avi") for k in (1, 2, 3, 4)]

def wall(cmd):
    start = time.perf_counter()
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    return time.perf_counter() - start

def median_ms(cmd, n=20):
    return statistics.median(wall(cmd) for _ in range(n)) * 1000

# Several inputs: --jobs 1 and --jobs 2 on the same 4 videos, alternated, median of 3 rounds.
inputs = [a for v in videos for a in ("-i", v)]
jobs = {1: [], 2: []}
for _ in range(3):
    for n in (1, 2):
        jobs[n].append(wall([softsight, "track", "-c", config, *inputs, "-o",
                             os.path.join(work, f"jobs{n}") + "/", "--jobs", str(n), "-q"]))
one, two = statistics.median(jobs[1]), statistics.median(jobs[2])
frames = 4 * 300
print(f"| `track` of 4 files (1200 frames) in one run: `--jobs 1` / `--jobs 2` | {frames / one:.0f} / "
      f"{frames / two:.0f} frames/s ({one / two:.2f}x) | one input already uses two threads "
      f"(decoding, tracking); load average {os.getloadavg()[0]:.1f} |")

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
