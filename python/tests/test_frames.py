"""softsight.frames: the frames of an input through the library's reader, one FrameResult each,
with the values of track's table; closing the generator early lets go of the video."""

from __future__ import annotations

import os
from pathlib import Path
from typing import List

import cv2
import pytest

import softsight
from test_track import as_text

MEASUREMENTS = ("angle_deg", "chord_px", "sagitta_px", "radius_px", "arc_length_px",
                "tip_disp_px", "chord_mm", "sagitta_mm", "radius_mm", "arc_length_mm",
                "tip_disp_mm")


def column_of(results: List[softsight.FrameResult], name: str, markers: List[str]) -> list:
    """The table column `name` rebuilt from the frames' results (None for an absent value)."""
    if name == "frame":
        return [r.frame for r in results]
    if name == "time_s":
        return [r.time_s for r in results]
    if name in MEASUREMENTS:
        return [r.measurement[name] for r in results]
    for marker in markers:
        if name.startswith(marker + "_"):
            attr = name[len(marker) + 1:]
            return [getattr(r[marker], attr) for r in results]
    raise AssertionError(f"column {name}: no FrameResult value for it")


def as_csv_text(values: list, name: str) -> List[str]:
    """Result values in the CSV's text, as test_track.as_text writes a table column."""
    out = []
    for v in values:
        if v is None:
            out.append("")
        elif isinstance(v, bool):
            out.append("1" if v else "0")
        elif isinstance(v, (int, str)):
            out.append(str(v))
        else:
            out.append(("%.6f" if name == "time_s" else "%.4f") % v)
    return out


def assert_frames_match_track(input, config) -> int:
    table = softsight.track(input, config)
    results = list(softsight.frames(input, config))
    assert len(results) == table.rows > 0
    markers = softsight.load_config(config).marker_names
    for name, column in table.items():
        if name == "proc_ms" or name.startswith("latency_"):
            continue  # Timings of each run's own clock.
        assert as_csv_text(column_of(results, name, markers), name) == as_text(column, name), name
    return len(results)


def test_every_frame_of_a_video_has_the_values_of_tracks_row(bending_video, markers_yaml):
    assert assert_frames_match_track(bending_video, markers_yaml) == 24


def test_a_predicted_video_gives_tracks_rows_after_its_key_frame_check(bending_video,
                                                                       markers_yaml, tmp_path):
    # MPEG-4 (a key frame every 12th frame as OpenCV writes it): frames() holds each group until
    # the next key frame is tracked, as track() does, and yields the same values in order.
    reader = cv2.VideoCapture(str(bending_video))
    mp4 = tmp_path / "bending.mp4"
    writer = cv2.VideoWriter(str(mp4), cv2.VideoWriter_fourcc(*"mp4v"), 30.0, (640, 480))
    while True:
        ok, image = reader.read()
        if not ok:
            break
        writer.write(image)
    writer.release()
    assert assert_frames_match_track(mp4, markers_yaml) == 24
    gen = softsight.frames(mp4, markers_yaml)
    assert [next(gen).frame for _ in range(3)] == [0, 1, 2]
    gen.close()


def test_a_rendered_scene_and_an_image_folder_too(markers_yaml, tmp_path):
    table = softsight.track("synth:bending", markers_yaml, max_frames=6)
    results = list(softsight.frames("synth:bending", markers_yaml, max_frames=6))
    assert [r.frame for r in results] == list(table["frame"]) == list(range(6))
    assert [round(r.angle_deg, 4) for r in results] == [round(v, 4) for v in table["angle_deg"]]
    # A folder of images: the reader's sequence rules (sorted names, timed at fps).
    scene = softsight.sim.Scene("bending", frames=5)
    for i in range(5):
        cv2.imwrite(str(tmp_path / f"f{i:03d}.png"), scene.render(i)[0])
    assert assert_frames_match_track(tmp_path, markers_yaml) == 5
    assert [r.time_s for r in softsight.frames(tmp_path, markers_yaml, fps=10.0)] == \
        pytest.approx([0.0, 0.1, 0.2, 0.3, 0.4])


def open_files() -> List[str]:
    """What this process has open (/proc/self/fd)."""
    names = []
    for fd in os.listdir("/proc/self/fd"):
        try:
            names.append(os.readlink(f"/proc/self/fd/{fd}"))
        except OSError:
            pass  # The listing's own descriptor, closed by now.
    return names


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs Linux's /proc/self/fd")
def test_closing_the_generator_early_releases_the_video(bending_video, markers_yaml):
    video = str(Path(bending_video).resolve())
    gen = softsight.frames(bending_video, markers_yaml)
    first = next(gen)
    assert first.frame == 0
    assert video in open_files()  # The reader holds the file while the loop runs ...
    gen.close()
    assert video not in open_files()  # ... and not after close().
    with pytest.raises(StopIteration):
        next(gen)
    # A loop left with break: the generator is closed when it is dropped.
    for r in softsight.frames(bending_video, markers_yaml):
        if r.frame == 2:
            break
    del r
    assert video not in open_files()
    # At the end of the input too.
    assert len(list(softsight.frames(bending_video, markers_yaml))) == 24
    assert video not in open_files()


def test_bad_input_raises_at_the_call_and_a_bad_frame_in_the_loop(bending_video, markers_yaml,
                                                                 tmp_path):
    missing = tmp_path / "missing.avi"
    with pytest.raises(softsight.InputError) as at_call:
        softsight.frames(missing, markers_yaml)  # Not deferred to the first next().
    with pytest.raises(softsight.InputError) as in_track:
        softsight.track(missing, markers_yaml)
    assert str(at_call.value) == str(in_track.value)
    with pytest.raises(softsight.InputError, match="max_frames: -1 must be >= 0"):
        softsight.frames(bending_video, markers_yaml, max_frames=-1)
    # A video cut mid-stream: the frames before it, then track's error.
    data = Path(bending_video).read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(softsight.InputError) as in_track:
        softsight.track(cut, markers_yaml)
    got = []
    with pytest.raises(softsight.InputError) as in_loop:
        for r in softsight.frames(cut, markers_yaml):
            got.append(r.frame)
    assert str(in_loop.value) == str(in_track.value)
    assert got == list(range(in_track.value.table.rows))
    # An empty folder: track's "no frames to read".
    empty = tmp_path / "empty"
    empty.mkdir()
    with pytest.raises(softsight.InputError) as in_track:
        softsight.track(empty, markers_yaml)
    with pytest.raises(softsight.InputError) as in_loop:
        list(softsight.frames(empty, markers_yaml))
    assert str(in_loop.value) == str(in_track.value)
