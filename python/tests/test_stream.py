"""softsight.stream: subscribe to a run's --publish while `softsight track` runs on the rendered
bending scene, and get every CSV row's values; a clear message without pandas. Needs pyzmq
(Debian: python3-zmq, which scripts/setup.sh installs)."""

from __future__ import annotations

import csv
import subprocess
from pathlib import Path

import pytest

from conftest import BINARY, SOURCE_DIR
from softsight import stream

zmq = pytest.importorskip("zmq", reason="pyzmq is not installed (Debian: apt install python3-zmq)")

TIMINGS = {"latency_result_ms", "latency_row_ms", "proc_ms"}  # Differ from run to run.


def same_value(field: str, value: object) -> bool:
    if field == "":
        return value is None
    if isinstance(value, str):
        return field == value
    return float(field) == float(value)  # type: ignore[arg-type]


def test_subscriber_gets_every_csv_row_with_its_values(tmp_path: Path) -> None:
    endpoint = f"ipc://{tmp_path}/s.ipc"
    out = tmp_path / "run.csv"
    # Subscribed before the run starts: --publish-wait 1 holds the first frame until it is.
    subscription = stream.subscribe(endpoint, timeout_s=60)
    run = subprocess.Popen(
        [str(BINARY), "track", "-c", str(SOURCE_DIR / "examples" / "markers.yaml"), "-i",
         "synth:bending", "-o", str(out), "--max-frames", "60", "--publish", endpoint,
         "--publish-wait", "1", "--quiet"],
        stderr=subprocess.PIPE, text=True)
    try:
        records = subscription.records()
        _, stderr = run.communicate(timeout=120)
    finally:
        if run.poll() is None:
            run.kill()
            run.wait()
    assert run.returncode == 0, stderr
    assert subscription.hello is not None and subscription.hello["version"] == stream.VERSION
    assert subscription.end is not None and subscription.end["frames"] == 60
    assert subscription.frame_gaps == 0
    with open(out, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    assert subscription.hello["columns"] == header
    assert len(records) == len(body) == 60
    for record, row in zip(records, body):
        assert list(record.keys()) == header
        for name, field in zip(header, row):
            if name not in TIMINGS:
                assert same_value(field, record[name]), (record["frame"], name, field, record[name])


def test_one_marker_topic_has_only_its_columns(tmp_path: Path) -> None:
    endpoint = f"ipc://{tmp_path}/s.ipc"
    subscription = stream.subscribe(endpoint, topic="marker/green", timeout_s=60)
    run = subprocess.run(
        [str(BINARY), "track", "-c", str(SOURCE_DIR / "examples" / "markers.yaml"), "-i",
         "synth:bending", "-o", str(tmp_path / "run.csv"), "--max-frames", "5", "--publish",
         endpoint, "--publish-wait", "1", "--quiet"],
        capture_output=True, text=True, timeout=120, check=False)
    records = subscription.records()
    assert run.returncode == 0, run.stderr
    assert [list(r.keys()) for r in records] == [
        ["frame", "time_s", "green_x", "green_y", "green_sigma_px", "green_found", "green_score",
         "green_status", "green_track"]] * 5


def test_to_dataframe_says_what_it_needs_without_pandas() -> None:
    try:
        import pandas  # noqa: F401
    except ImportError:
        with pytest.raises(ImportError, match="needs pandas"):
            stream.to_dataframe([{"frame": 0}])
    else:
        frame = stream.to_dataframe([{"frame": 0, "angle_deg": 150.5}, {"frame": 1, "angle_deg": None}])
        assert list(frame.columns) == ["frame", "angle_deg"]


def test_bad_address_and_topic_are_refused() -> None:
    with pytest.raises(ValueError, match="not an endpoint"):
        stream.subscribe("udp://x:1")
    with pytest.raises(ValueError, match="topic"):
        stream.subscribe("tcp://127.0.0.1:1", topic="frame measure")
