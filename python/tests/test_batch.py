"""track_many on a LocalCluster with 2 workers: 4 short videos, one of them corrupt. The good
ones give the same rows as serial runs, the corrupt one one clear failure."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softsight
from conftest import read_csv, render_video

distributed = pytest.importorskip("distributed")
import softsight.batch  # noqa: E402  (after the skip: needs Dask)


@pytest.fixture(scope="module", autouse=True)
def dask_folder(tmp_path_factory):
    """Dask's workers keep their scratch folders (dask-worker-space) in the temporary directory
    unless told: here, inside this test's own, so the suite leaves nothing behind."""
    import dask

    with dask.config.set({"temporary-directory": str(tmp_path_factory.mktemp("dask"))}):
        yield


@pytest.fixture(scope="module")
def videos(tmp_path_factory):
    folder = tmp_path_factory.mktemp("batch")
    good = [render_video(folder / f"run{seed}.avi", frames=12, seed=seed) for seed in (1, 2, 3)]
    corrupt = folder / "broken.avi"
    data = good[0].read_bytes()
    corrupt.write_bytes(data[: len(data) // 2])  # Cut off mid-stream, as a crashed recorder.
    return good[:2] + [corrupt] + good[2:]


def test_track_many_on_a_local_cluster(videos, markers_yaml, tmp_path):
    out = tmp_path / "out"
    calls = []
    table = softsight.batch.track_many(videos, str(markers_yaml), out_dir=out, timeout_s=90,
                                       progress=lambda done, total: calls.append((done, total)))
    assert list(table["input"]) == [str(v) for v in videos]
    assert calls == [(1, 4), (2, 4), (3, 4), (4, 4)]  # One per input, the failed one too.
    assert list(table["ok"]) == [True, True, False, True]
    # The corrupt input: one clear error naming the file, as the CLI reports it.
    with pytest.raises(softsight.InputError) as serial_error:
        softsight.track(videos[2], markers_yaml)
    assert table["error"][2] == str(serial_error.value) and str(videos[2]) in table["error"][2]
    assert table["stop_reason"][2] == "error"
    # The good ones: the same rows as serial runs, written one CSV per input.
    for i in (0, 1, 3):
        assert table["error"][i] == "" and table["frames"][i] == 12
        assert table["found_red"][i] == 1.0 and table["stop_reason"][i] == "end of input"
        serial = softsight.track(videos[i], markers_yaml)
        written = read_csv(table["csv"][i])
        assert list(written) == list(serial)
        for name, column in serial.items():
            if name == "proc_ms" or name.startswith("latency_"):
                continue
            if column.dtype == np.float64:
                got = [float(v) if v else math.nan for v in written[name]]
                np.testing.assert_array_equal(np.array(got), column, err_msg=name)
            elif column.dtype == np.bool_:
                assert written[name] == ["1" if v else "0" for v in column], name
            else:
                assert written[name] == [str(v) for v in column], name
    # The work was spread over the cluster's two workers' slots (any of them may take any task).
    assert all(w for w in table["worker"])
    assert sorted(p.name for p in out.iterdir()) == ["broken.csv", "run1.csv", "run2.csv", "run3.csv"]


def test_a_bad_config_fails_before_anything_runs(videos, tmp_path):
    with pytest.raises(softsight.InputError, match=r"^<dict>: markers: expected a list"):
        softsight.batch.track_many(videos, {"markers": 3}, out_dir=tmp_path)
    assert not any(tmp_path.iterdir())


def test_csv_names_are_unique():
    from pathlib import Path

    names = softsight.batch._csv_names(["a/run.avi", "b/run.avi", "synth:bending"], Path("o"))
    assert names == ["o/run.csv", "o/run-1.csv", "o/synth_bending.csv"]


def run_script(tmp_path, name: str, body: str):
    """`body` as the script `name`, run by a fresh interpreter (its temporary files in tmp_path)."""
    import os
    import subprocess
    import sys

    script = tmp_path / name
    script.write_text(body)
    env = dict(os.environ, TMPDIR=str(tmp_path))  # Dask's worker folders go there, not /tmp.
    return subprocess.run([sys.executable, str(script)], capture_output=True, text=True,
                          timeout=120, cwd=tmp_path, env=env)


def test_processes_true_runs_under_the_main_guard(markers_yaml, tmp_path):
    result = run_script(tmp_path, "guarded.py", f"""
import softsight.batch


def main():
    table = softsight.batch.track_many(["synth:bending", "synth:wedge1"], {str(markers_yaml)!r},
                                       out_dir="out", max_frames=3, processes=True, timeout_s=90)
    print(list(table["ok"]), list(table["frames"]))


if __name__ == "__main__":
    main()
""")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "[True, True] [3, 3]"
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["synth_bending.csv",
                                                                     "synth_wedge1.csv"]


def test_processes_true_without_the_guard_is_one_clear_error(markers_yaml, tmp_path):
    # Without the check, each worker re-imports the script, starts a cluster of its own, dies
    # and is restarted by Dask without end (the script never returns).
    result = run_script(tmp_path, "unguarded.py", f"""
import softsight.batch
softsight.batch.track_many(["synth:bending"], {str(markers_yaml)!r}, out_dir="out",
                           max_frames=3, processes=True)
""")
    assert result.returncode == 1
    last = result.stderr.strip().splitlines()[-1]
    assert last.startswith("RuntimeError: softsight.batch.track_many(processes=True): ")
    assert "unguarded.py line 3 calls it when the script is imported" in last
    assert 'if __name__ == "__main__":' in last
    assert not (tmp_path / "out").exists()  # Refused before anything was made.
