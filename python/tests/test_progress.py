"""progress=: a callable gets (done, total) after every frame; True draws through Python's
sys.stderr (tqdm when installed, a plain line otherwise), so redirect_stderr sees it; nothing
reaches the process's fd 2."""

from __future__ import annotations

import contextlib
import io
import subprocess
import sys

import pytest

import softsight

FRAMES = 8


def no_tqdm(monkeypatch):
    """As if tqdm were not installed (both names: tqdm.auto may be imported already)."""
    monkeypatch.setitem(sys.modules, "tqdm", None)
    monkeypatch.setitem(sys.modules, "tqdm.auto", None)


def test_a_callback_gets_every_frame_with_the_total(markers_yaml):
    calls = []
    table = softsight.track("synth:bending", markers_yaml, max_frames=FRAMES,
                            progress=lambda done, total: calls.append((done, total)))
    assert table.rows == FRAMES
    assert calls == [(n, FRAMES) for n in range(1, FRAMES + 1)]
    # frames(): one call per frame yielded, before it is yielded.
    calls.clear()
    seen = []
    for r in softsight.frames("synth:bending", markers_yaml, max_frames=FRAMES,
                              progress=lambda done, total: calls.append((done, total))):
        seen.append(r.frame)
        assert calls[-1] == (r.frame + 1, FRAMES)
    assert seen == list(range(FRAMES)) and len(calls) == FRAMES


def test_an_exception_in_the_callback_ends_the_run_and_is_raised(markers_yaml):
    calls = []

    def stop_at_three(done, total):
        calls.append(done)
        if done == 3:
            raise KeyError("enough")

    with pytest.raises(KeyError, match="enough"):
        softsight.track("synth:bending", markers_yaml, max_frames=FRAMES, progress=stop_at_three)
    assert calls == [1, 2, 3]  # Not called again once it failed.


def test_true_without_tqdm_writes_a_line_to_sys_stderr(markers_yaml, monkeypatch):
    no_tqdm(monkeypatch)
    log = io.StringIO()
    with contextlib.redirect_stderr(log):
        softsight.track("synth:bending", markers_yaml, max_frames=FRAMES, progress=True)
    text = log.getvalue()
    assert text.endswith(f"\rtrack: {FRAMES} / {FRAMES} frames\n"), repr(text)
    log = io.StringIO()
    with contextlib.redirect_stderr(log):
        assert len(list(softsight.frames("synth:bending", markers_yaml, max_frames=3,
                                         progress=True))) == 3
    assert log.getvalue().endswith("\rframes: 3 / 3 frames\n"), repr(log.getvalue())


def test_true_with_tqdm_draws_a_tqdm_bar_on_sys_stderr(markers_yaml):
    pytest.importorskip("tqdm", reason="python3-tqdm not installed (scripts/setup.sh installs it)")
    log = io.StringIO()
    with contextlib.redirect_stderr(log):
        softsight.track("synth:bending", markers_yaml, max_frames=FRAMES, progress=True)
    text = log.getvalue()
    assert "track: 100%" in text and f"{FRAMES}/{FRAMES}" in text, repr(text)


def test_false_and_none_are_silent_and_anything_else_is_a_type_error(markers_yaml,
                                                                      monkeypatch):
    no_tqdm(monkeypatch)
    for quiet in (False, None):
        log = io.StringIO()
        with contextlib.redirect_stderr(log):
            softsight.track("synth:bending", markers_yaml, max_frames=2, progress=quiet)
        assert log.getvalue() == ""
    with pytest.raises(TypeError, match=r"^progress: True .* got str 'yes'"):
        softsight.track("synth:bending", markers_yaml, max_frames=2, progress="yes")
    with pytest.raises(TypeError, match=r"^progress: .* got int 1"):
        softsight.frames("synth:bending", markers_yaml, progress=1)


def test_nothing_reaches_the_process_fd_2(markers_yaml, tmp_path):
    # In a child whose fd 2 is a file: progress=True with stderr redirected in Python leaves
    # that file empty, and the line is in the redirect.
    code = (
        "import contextlib, io, sys\n"
        "sys.modules['tqdm'] = sys.modules['tqdm.auto'] = None\n"
        "import softsight\n"
        "log = io.StringIO()\n"
        "with contextlib.redirect_stderr(log):\n"
        f"    softsight.track('synth:bending', {str(markers_yaml)!r}, max_frames=4, progress=True)\n"
        "print(repr(log.getvalue()))\n"
    )
    with open(tmp_path / "fd2.txt", "w+") as fd2:
        out = subprocess.run([sys.executable, "-c", code], stdout=subprocess.PIPE, stderr=fd2,
                             text=True, timeout=120, check=True)
        fd2.seek(0)
        assert fd2.read() == ""
    assert "track: 4 / 4 frames" in out.stdout
