#!/usr/bin/env python3
"""Per-frame overhead of softsight.Session.process over the C++ TrackingSession::process call.

Run on demand (not a test; timing never fails a test):
    PYTHONPATH=build/python /usr/bin/python3 python/bench/session_overhead.py

One VGA frame of the bending scene (3 colour markers, examples/markers.yaml) is processed over and
over, alternating blocks of calls from Python (Session.process: the numpy buffer wrapped in a
cv::Mat header, the GIL released and taken back, the per-session lock, the result copied into a
Python object) and blocks of the same calls made in C++ by the binding on the same session
(TrackingSession::process alone).

On a loaded machine the tracking time of one frame varies by tens of microseconds, more than the
overhead, so the figure is paired per call: each Session.process call is timed from Python and
its own C++ time (FrameResult.proc_ms, measured inside TrackingSession::process) subtracted; the
median of those differences is the overhead (it includes the two perf_counter calls and
TrackingSession::process's own bookkeeping outside proc_ms, so it slightly overstates). The
block comparison (Python loop vs C++ loop, medians) is printed beside it as a cross-check.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import softsight


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=40, help="alternating blocks of each kind")
    parser.add_argument("--calls", type=int, default=200, help="calls per block")
    parser.add_argument("--config", default=str(Path(__file__).resolve().parents[2] / "examples" / "markers.yaml"))
    args = parser.parse_args()

    image, _ = softsight.sim.Scene("bending", size=(640, 480)).render(0)
    session = softsight.Session(args.config)
    for _ in range(200):  # Warm up: trackers acquire, caches fill.
        session.process(image, 0.0)
    assert all(m.found for m in session.process(image, 0.0).markers)

    python_us, cpp_us, paired_us = [], [], []
    clock = time.perf_counter
    for _ in range(args.blocks):
        start = clock()
        for _ in range(args.calls):
            session.process(image, 0.0)
        python_us.append((clock() - start) / args.calls * 1e6)
        cpp_us.append(session._time_cpp_process(image, args.calls) / args.calls * 1e6)
        for _ in range(args.calls):
            t0 = clock()
            r = session.process(image, 0.0)
            t1 = clock()
            paired_us.append((t1 - t0) * 1e6 - r.proc_ms * 1e3)

    py_med, cpp_med = statistics.median(python_us), statistics.median(cpp_us)
    diffs = sorted(p - c for p, c in zip(python_us, cpp_us))
    q1, q3 = diffs[len(diffs) // 4], diffs[(3 * len(diffs)) // 4]
    print(f"VGA frame, 3 markers, {args.blocks} x {args.calls} calls of each kind")
    print(f"Session.process from Python : {py_med:8.2f} us per frame (median of blocks)")
    print(f"TrackingSession::process C++: {cpp_med:8.2f} us per frame")
    paired_us.sort()
    n = len(paired_us)
    print(f"block medians differ by     : {py_med - cpp_med:8.2f} us per frame "
          f"(per-block differences: quartiles {q1:.2f} .. {q3:.2f} us)")
    print(f"overhead, paired per call   : {paired_us[n // 2]:8.2f} us per frame median "
          f"(quartiles {paired_us[n // 4]:.2f} .. {paired_us[3 * n // 4]:.2f} us, {n} calls; "
          f"target <= 5 us)")


if __name__ == "__main__":
    main()
