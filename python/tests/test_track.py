"""softsight.track on a rendered video gives exactly the CLI's CSV values."""

from __future__ import annotations

import math
import os
import sys
from pathlib import Path

import numpy as np
import pytest

import softsight
from conftest import cli_error, read_csv, run_cli


def as_text(column: np.ndarray, name: str) -> list:
    """An array back in the CSV's text, to compare field by field."""
    if column.dtype == np.bool_:
        return ["1" if v else "0" for v in column]
    if column.dtype.kind == "U":
        return [str(v) for v in column]
    if column.dtype == np.int64:
        return [str(v) for v in column]
    fmt = "%.6f" if name == "time_s" else "%.4f"
    return ["" if math.isnan(v) else fmt % v for v in column]


def test_track_gives_exactly_the_cli_csv(bending_video, markers_yaml, tmp_path):
    out = tmp_path / "cli.csv"
    run_cli("track", "-c", str(markers_yaml), "-i", str(bending_video), "-o", str(out), "-q")
    expected = read_csv(out)
    table = softsight.track(bending_video, markers_yaml, csv=tmp_path / "py.csv")
    assert list(table) == list(expected)  # Same columns, same order.
    assert table.rows == 24
    for name, column in table.items():
        assert len(column) == 24
        if name == "proc_ms":
            assert column.dtype == np.float64 and np.all(column > 0)
            continue
        if name.startswith("latency_"):  # Timings too, from this run's clock.
            continue
        assert as_text(column, name) == expected[name], name
        # The arrays hold the file's numbers exactly (not re-rounded values).
        if column.dtype == np.float64:
            parsed = np.array([float(v) if v else np.nan for v in expected[name]])
            np.testing.assert_array_equal(column, parsed)
    assert table["frame"].dtype == np.int64 and table["red_found"].dtype == np.bool_
    assert table["blue_status"][0] == "found" and table["red_found"].all()
    # csv= writes the CLI's file (apart from the timing column).
    written = read_csv(tmp_path / "py.csv")
    for timing in ("proc_ms", "latency_result_ms", "latency_row_ms"):
        del written[timing], expected[timing]
    assert written == expected
    summary = table.summary
    assert summary["frames"] == 24 and summary["stop_reason"] == "end of input"
    assert summary["found_rate"] == {"red": 1.0, "blue": 1.0, "green": 1.0}
    assert summary["error"] is None
    # The CSV sink's own figure (FrameSink::report), as `track` prints it: capture to row written
    # comes after capture to result.
    assert summary["latency_row_ms_median"] is not None
    assert summary["latency_row_ms_median"] >= summary["latency_result_ms_median"] > 0


def test_track_a_builtin_scene_with_max_frames(markers_yaml, tmp_path):
    out = tmp_path / "cli.csv"
    run_cli("track", "-c", str(markers_yaml), "-i", "synth:bending", "--max-frames", "5",
            "-o", str(out), "-q")
    expected = read_csv(out)
    table = softsight.track("synth:bending", markers_yaml, max_frames=5)
    assert table.rows == 5 and table.summary["stop_reason"] == "max frames reached"
    assert table.summary["latency_row_ms_median"] is None  # No CSV written, no row latency.
    for name in expected:
        if name != "proc_ms" and not name.startswith("latency_"):
            assert as_text(table[name], name) == expected[name], name


def test_a_missing_input_gives_the_cli_message(markers_yaml, tmp_path):
    missing = tmp_path / "missing.avi"
    expected = cli_error("track", "-c", str(markers_yaml), "-i", str(missing), "-o",
                         str(tmp_path / "x.csv"))
    with pytest.raises(softsight.InputError) as error:
        softsight.track(missing, markers_yaml)
    assert str(error.value) == expected and str(missing) in expected


def test_a_corrupt_video_fails_with_the_rows_before(bending_video, markers_yaml, tmp_path):
    data = bending_video.read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) * 2 // 3])  # Ends mid-stream.
    expected = cli_error("track", "-c", str(markers_yaml), "-i", str(cut), "-o",
                         str(tmp_path / "x.csv"))
    with pytest.raises(softsight.InputError) as error:
        softsight.track(cut, markers_yaml)
    assert str(error.value) == expected
    assert 0 < error.value.table.rows < 24


def test_to_pandas_without_pandas_raises_a_clear_import_error(monkeypatch):
    table = softsight.Table({"frame": np.arange(3)})
    monkeypatch.setitem(sys.modules, "pandas", None)  # As if pandas were not installed.
    with pytest.raises(ImportError, match="to_pandas\\(\\) needs pandas, which is not installed"):
        table.to_pandas()


def test_to_pandas_with_pandas():
    pandas = pytest.importorskip("pandas")
    frame = softsight.Table({"frame": np.arange(3), "angle_deg": np.array([180.0, np.nan, 90.0])}).to_pandas()
    assert isinstance(frame, pandas.DataFrame) and list(frame.columns) == ["frame", "angle_deg"]


def test_the_csv_never_overwrites_the_video_or_the_config(bending_video, markers_yaml, tmp_path):
    video = tmp_path / "v.avi"
    video.write_bytes(bending_video.read_bytes())
    config = tmp_path / "m.yaml"
    config.write_text(Path(markers_yaml).read_text())
    before = (video.read_bytes(), config.read_text())
    for target in (video, config, tmp_path / "." / "m.yaml"):
        with pytest.raises(softsight.InputError) as error:
            softsight.track(video, config, csv=target)
        assert "refusing to overwrite an input" in str(error.value)
    assert (video.read_bytes(), config.read_text()) == before


def test_bytes_and_pathlib_paths_name_the_same_file_and_a_nul_is_refused(bending_video,
                                                                          markers_yaml):
    as_text = softsight.track(str(bending_video), markers_yaml, max_frames=3)
    as_bytes = softsight.track(os.fsencode(bending_video), os.fsencode(markers_yaml),
                               max_frames=3)
    assert as_bytes.rows == as_text.rows == 3
    assert list(as_bytes["angle_deg"]) == list(as_text["angle_deg"])
    with pytest.raises(softsight.InputError) as error:
        softsight.track(str(bending_video) + "\0x", markers_yaml)
    assert "a path holding a NUL byte" in str(error.value)
