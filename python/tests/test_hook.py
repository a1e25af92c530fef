"""softsight.track(hook=...): a Python callable's values as columns of the table and the CSV,
the same as `softsight track --hook` writes; a hook that raises is reported once and switched
off, or stops the run; a wrong value raises InputError naming it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softsight
from conftest import read_csv, run_cli


def x_sum(frame, result):
    """The three markers' x summed (when all are found), and the frame's mean green."""
    assert isinstance(frame, np.ndarray) and frame.ndim == 3 and frame.dtype == np.uint8
    assert not frame.flags.writeable
    values = {"mean_green": float(frame[:, :, 1].mean())}
    if all(m.found for m in result.markers):
        values["x_sum"] = sum(m.x for m in result.markers)
    return values


x_sum.columns = ["x_sum", "mean_green"]


def test_the_hooks_columns_hold_what_it_computed(bending_video, markers_yaml, tmp_path):
    table = softsight.track(bending_video, markers_yaml, hook=x_sum, csv=tmp_path / "py.csv")
    names = list(table)
    assert names.index("mean_green") == names.index("x_sum") + 1
    assert names.index("mean_green") < names.index("latency_result_ms")
    found = ~np.isnan(table["x_sum"])
    assert found.sum() >= table.rows - 2
    markers = [n[: -len("_x")] for n in names if n.endswith("_x")]
    expected = sum(table[m + "_x"] for m in markers)
    np.testing.assert_allclose(table["x_sum"][found], expected[found], atol=1e-3)
    assert np.all((table["mean_green"] > 0) & (table["mean_green"] < 255))
    assert table.summary["hook_error"] is None
    assert any("hook: values in %d of %d rows" % (table.rows, table.rows) in n
               for n in table.summary["notes"])


def test_the_cli_hook_writes_the_same_column(bending_video, markers_yaml, tmp_path):
    hook = tmp_path / "h.py"
    hook.write_text(
        "columns = ['x_sum', 'mean_green']\n"
        "def on_frame(frame, result):\n"
        "    values = {'mean_green': float(frame[:, :, 1].mean())}\n"
        "    if all(m.found for m in result.markers):\n"
        "        values['x_sum'] = sum(m.x for m in result.markers)\n"
        "    return values\n"
    )
    out = tmp_path / "cli.csv"
    run_cli("track", "-c", str(markers_yaml), "-i", str(bending_video), "-o", str(out), "-q",
            "--hook", str(hook))
    cli = read_csv(out)
    table = softsight.track(bending_video, markers_yaml, hook=x_sum, hook_columns=("x_sum", "mean_green"))
    assert list(cli) == list(table)
    for name in ("x_sum", "mean_green"):
        mine = ["" if math.isnan(v) else float(v) for v in table[name]]
        theirs = ["" if v == "" else float(v) for v in cli[name]]
        assert mine == pytest.approx(theirs, abs=1e-6)


def test_a_hook_that_raises_is_reported_once_and_switched_off(bending_video, markers_yaml, capsys):
    calls = []

    def hook(frame, result):
        calls.append(result.frame)
        return {"inverse": 1 / (5 - result.frame)}

    table = softsight.track(bending_video, markers_yaml, hook=hook, hook_columns=["inverse"])
    assert calls == [0, 1, 2, 3, 4, 5]
    assert list(np.isnan(table["inverse"])) == [i >= 5 for i in range(table.rows)]
    err = capsys.readouterr().err
    assert err.count("Traceback") == 1 and "ZeroDivisionError: division by zero" in err
    assert "ZeroDivisionError" in table.summary["hook_error"]

    with pytest.raises(softsight.InputError, match="hook failed at frame 5: ZeroDivisionError"):
        softsight.track(bending_video, markers_yaml, hook=hook, hook_columns=["inverse"],
                        hook_stop_on_error=True)


def test_wrong_values_and_columns_raise_input_error(bending_video, markers_yaml):
    with pytest.raises(softsight.InputError, match="on_frame returned 'x' for 'a': not a number"):
        softsight.track(bending_video, markers_yaml, hook=lambda f, r: {"a": "x"}, hook_columns=["a"])
    with pytest.raises(softsight.InputError, match=r"'b' is not one of the hook's columns \(a\)"):
        softsight.track(bending_video, markers_yaml, hook=lambda f, r: {"b": 1}, hook_columns=["a"])
    with pytest.raises(softsight.InputError, match="column 'red_x' is already a column"):
        softsight.track(bending_video, markers_yaml, hook=lambda f, r: None, hook_columns=["red_x"])
    with pytest.raises(TypeError, match="hook_columns"):
        softsight.track(bending_video, markers_yaml, hook=lambda f, r: None)
