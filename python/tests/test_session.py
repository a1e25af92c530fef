"""Session.process on frames from OpenCV's Python VideoCapture: the same results as the CLI,
read in place (no copy), with the GIL released; bad frames raise InputError."""

from __future__ import annotations

import threading

import cv2
import numpy as np
import pytest

import softsight
from conftest import read_csv, run_cli


def field(value, fmt: str = "%.4f") -> str:
    """A value as the CSV writes it (empty when absent)."""
    return "" if value is None else fmt % value


def test_process_on_videocapture_frames_matches_the_cli_csv(bending_video, markers_yaml, tmp_path):
    out = tmp_path / "cli.csv"
    run_cli("track", "-c", str(markers_yaml), "-i", str(bending_video), "-o", str(out), "-q")
    expected = read_csv(out)

    session = softsight.Session(str(markers_yaml))
    cap = cv2.VideoCapture(str(bending_video))
    got = {name: [] for name in expected}
    frames = 0
    while True:
        ok, frame = cap.read()
        if not ok:
            break
        r = session.process(frame, time_s=frames / 30.0)
        assert r.frame == frames
        got["frame"].append(str(r.frame))
        for m in r.markers:
            got[f"{m.name}_x"].append(field(m.x))
            got[f"{m.name}_y"].append(field(m.y))
            got[f"{m.name}_sigma_px"].append(field(m.sigma_px))
            got[f"{m.name}_found"].append("1" if m.found else "0")
            got[f"{m.name}_score"].append(field(m.score))
            got[f"{m.name}_status"].append(m.status)
            got[f"{m.name}_track"].append(m.track)
        for name in ("angle_deg", "chord_px", "sagitta_px", "radius_px", "arc_length_px",
                     "tip_disp_px", "chord_mm", "sagitta_mm", "radius_mm", "arc_length_mm",
                     "tip_disp_mm"):
            got[name].append(field(getattr(r, name)))
        frames += 1
    assert frames == 24
    for name in expected:
        # time_s: this loop's own clock; proc_ms, latency_*: timings.
        if name in ("time_s", "proc_ms") or name.startswith("latency_"):
            continue
        assert got[name] == expected[name], name
    # The scene is tracked, not just echoed: every marker found in every frame.
    assert all(v == "1" for v in expected["red_found"] + expected["green_found"])
    assert r["blue"].found and r["blue"] is not None and r.angle_deg < 180.0


def test_a_bgr_frame_is_read_in_place(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    frame = np.zeros((480, 640, 3), np.uint8)
    session.process(frame, 0.0)
    assert session._last_frame_address == frame.ctypes.data  # The library read these pixels.
    # A crop of a bigger image is a view with a longer row step: still no copy.
    big = np.zeros((600, 800, 3), np.uint8)
    crop = big[50:530, 100:740]
    session.process(crop, 0.1)
    assert session._last_frame_address == crop.ctypes.data
    address, rows, cols, channels, step, copied = softsight._core._image_header(crop)
    assert (address, rows, cols, channels, step, copied) == (crop.ctypes.data, 480, 640, 3, 2400, False)


def test_layouts_that_need_a_copy_or_expansion():
    flipped = np.zeros((48, 64, 3), np.uint8)[:, ::-1]
    *_, copied = softsight._core._image_header(flipped)
    assert copied
    gray = np.zeros((48, 64), np.uint8)
    address, rows, cols, channels, step, copied = softsight._core._image_header(gray)
    assert (address, channels, copied) == (gray.ctypes.data, 1, False)


def test_gray_frames_are_tracked_like_their_bgr_expansion():
    # A white dot on a dark gray plate, as a mono camera sees it; centre (200.25, 150.75).
    gray = np.full((240, 320), 60, np.uint8)
    cv2.circle(gray, (200 * 16 + 4, 150 * 16 + 12), 9 * 16, 230, -1, cv2.LINE_AA, shift=4)
    config = {"markers": [{"name": "dot", "gray": [150, 255]}]}
    from_gray = softsight.Session(config).process(gray, 0.0)["dot"]
    from_bgr = softsight.Session(config).process(cv2.cvtColor(gray, cv2.COLOR_GRAY2BGR), 0.0)["dot"]
    assert from_gray.found and from_gray.status == "found"
    assert abs(from_gray.x - 200.25) < 0.1 and abs(from_gray.y - 150.75) < 0.1
    assert (from_gray.x, from_gray.y, from_gray.score) == (from_bgr.x, from_bgr.y, from_bgr.score)


def test_the_gil_is_released_while_a_frame_is_processed(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    frame = np.zeros((480, 640, 3), np.uint8)
    session.process(frame, 0.0)
    assert session._last_call_released_gil
    # Two threads on one session: each call runs whole (a lock per session), indices in order.
    results = []
    threads = [threading.Thread(target=lambda: results.append(session.process(frame, 0.0).frame))
               for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    assert sorted(results) == [1, 2, 3, 4]


@pytest.mark.parametrize(
    "frame, message",
    [
        (np.zeros((480, 640, 3), np.float32),
         "frame 0: a float32 array; softsight needs uint8 pixels (an HxWx3 BGR or HxW gray array, "
         "as cv2.VideoCapture.read() gives)"),
        (np.zeros((480, 640, 3), np.int16),
         "frame 0: an int16 array; softsight needs uint8 pixels (an HxWx3 BGR or HxW gray array, "
         "as cv2.VideoCapture.read() gives)"),
        (np.zeros((480, 640, 4), np.uint8),
         "frame 0: an array of shape (480, 640, 4); softsight needs HxWx3 (BGR) or HxW (gray) pixels"),
        (np.zeros((640,), np.uint8),
         "frame 0: an array of shape (640,); softsight needs HxWx3 (BGR) or HxW (gray) pixels"),
        (np.zeros((0, 640, 3), np.uint8),
         "frame 0: an array of shape (0, 640, 3); softsight needs HxWx3 (BGR) or HxW (gray) pixels"),
    ],
)
def test_bad_frames_raise_input_error(markers_yaml, frame, message):
    session = softsight.Session(str(markers_yaml))
    with pytest.raises(softsight.InputError) as error:
        session.process(frame, 0.0)
    assert str(error.value) == message
    assert isinstance(error.value, ValueError)
    assert session.next_index == 0  # Nothing was processed.


def test_a_frame_of_another_size_raises_input_error(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    session.process(np.zeros((480, 640, 3), np.uint8), 0.0)
    with pytest.raises(softsight.InputError, match=r"^frame 1: 320x240 pixels, but this session's "
                                                   r"frames are 640x480"):
        session.process(np.zeros((240, 320, 3), np.uint8), 0.1)


def test_result_fields_are_none_where_the_csv_is_empty(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    r = session.process(np.full((480, 640, 3), 128, np.uint8), 0.0)  # No markers at all.
    for m in r.markers:
        assert (m.found, m.x, m.y) == (False, None, None)
        assert m.status in ("lost", "ambiguous", "implausible", "covered", "out_of_frame")
    assert r.angle_deg is None and r.radius_px is None and r.tip_disp_mm is None
    assert r.measurement["chord_px"] is None
    with pytest.raises(KeyError):
        r["nobody"]
    assert session.columns[:2] == ["frame", "time_s"] and session.columns[-1] == "proc_ms"


def test_gray_frames_with_colour_markers_raise_like_track_does(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    with pytest.raises(softsight.InputError) as error:
        session.process(np.zeros((480, 640), np.uint8), 0.0)
    assert "gray frame" in str(error.value) and "colour tracking needs colour" in str(error.value)


def test_a_time_that_is_not_a_finite_non_negative_number_is_refused(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    frame = np.zeros((480, 640, 3), np.uint8)
    for bad in (float("nan"), float("inf"), -0.5):
        with pytest.raises(softsight.InputError) as error:
            session.process(frame, bad)
        assert "time_s" in str(error.value)
    with pytest.raises(softsight.InputError) as error:
        session.process(frame, 0.0, -3)
    assert "frame -3: a frame index must be >= 0" in str(error.value)
    assert session.process(frame, 0.0).frame == 0  # Nothing refused was counted.


def test_a_list_as_frame_is_a_short_type_error(markers_yaml):
    session = softsight.Session(str(markers_yaml))
    with pytest.raises(TypeError) as error:
        session.process([[0] * 640] * 480, 0.0)
    assert "frame: a numpy array" in str(error.value) and len(str(error.value)) < 200
