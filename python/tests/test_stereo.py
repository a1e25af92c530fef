"""softsight.track_stereo: the same columns as `softsight track-stereo`, and exact 3D on a rig whose
geometry is known by construction.

Both views are the built-in bending scene (the same frames). The right camera of the rig sits
100 mm to the right with its principal point 200 px further right, so one pixel in both views is a
point at Z = f B / 200 px = 300 mm: the actuator lies in the plane Z = 300 mm, parallel to the
image, and its 3D angle is exactly the angle one camera measures.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

import softsight
from conftest import cli_error, run_cli

STEREO_YAML = """%YAML:1.0
---
image_width: 640
image_height: 480
camera_matrix_left: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 600., 0., 320., 0., 600., 240., 0., 0., 1. ]
distortion_left: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0., 0., 0., 0., 0. ]
camera_matrix_right: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 600., 0., 520., 0., 600., 240., 0., 0., 1. ]
distortion_right: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 0., 0., 0., 0., 0. ]
R: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 1., 0., 0., 0., 1., 0., 0., 0., 1. ]
T: !!opencv-matrix
   rows: 3
   cols: 1
   dt: d
   data: [ -100., 0., 0. ]
"""


@pytest.fixture
def stereo_yaml(tmp_path) -> Path:
    path = tmp_path / "stereo.yaml"
    path.write_text(STEREO_YAML)
    return path


def test_track_stereo_gives_the_cli_columns_and_exact_3d(markers_yaml, stereo_yaml, tmp_path):
    # The same scene in both views, started together (a smooth sweep: the motion alone would not
    # tell the offset, see the refusal test below).
    table = softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                                   max_frames=6, frame_offset=0)
    csv_path = tmp_path / "run3d.csv"
    run_cli("track-stereo", "-c", str(markers_yaml), "--left", "synth:bending", "--right",
            "synth:bending", "--stereo", str(stereo_yaml), "--csv", str(csv_path),
            "--max-frames", "6", "--frame-offset", "0")
    with open(csv_path, newline="") as f:
        rows = list(csv.DictReader(f))
    assert list(table) == list(rows[0])
    assert len(table["frame"]) == len(rows) == 6
    assert table.summary["pairs"] == 6
    for name in ("red", "blue", "green"):
        assert list(table[f"{name}_status"]) == ["found"] * 6
        assert table.summary["found"][name] == 6
        np.testing.assert_allclose(table[f"{name}_Z"], 300.0, atol=1e-3)
        np.testing.assert_allclose(table[f"{name}_X"], [float(r[f"{name}_X"]) for r in rows])
    # In a plane parallel to the image the 3D angle is the 2D one, and the plane is the image's.
    np.testing.assert_allclose(table["angle_deg"], table["angle_left_deg"], atol=1e-3)
    out_of_plane = table["out_of_plane_deg"]
    defined = ~np.isnan(out_of_plane)  # Not while the three markers are exactly on a line.
    assert defined.sum() >= 3
    np.testing.assert_allclose(out_of_plane[defined], 0.0, atol=1e-3)
    assert table["frame"].dtype == np.int64


def test_bad_input_gives_the_cli_message(markers_yaml, stereo_yaml, tmp_path):
    with pytest.raises(softsight.InputError, match="missing.yaml: cannot open"):
        softsight.track_stereo("synth:bending", "synth:bending", markers_yaml,
                               tmp_path / "missing.yaml")
    with pytest.raises(softsight.InputError, match="reference_plane: expected image"):
        softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                               reference_plane="sideways")


def _write_pgm(path: Path, image: np.ndarray) -> None:
    with open(path, "wb") as f:
        f.write(b"P5\n%d %d\n255\n" % (image.shape[1], image.shape[0]) + image.tobytes())


def test_bench_board_puts_the_markers_in_the_boards_frame(markers_yaml, stereo_yaml, tmp_path):
    # A 9x6 board (10x7 squares of 40 px = 20 mm at 300 mm, dark square at the top-left) drawn
    # facing the rig in the plane Z = 300 mm: one picture serves both views (see the rig above).
    # Its frame is the camera's turned by nothing, with the origin at its first inner corner,
    # pixel (159.5, 139.5): (-80.25, -50.25, 300) mm.
    board = np.full((480, 640), 110, np.uint8)
    board[80:400, 100:540] = 230
    for i in range(10):
        for j in range(7):
            if (i + j) % 2 == 0:
                board[100 + 40 * j:140 + 40 * j, 120 + 40 * i:160 + 40 * i] = 25
    _write_pgm(tmp_path / "bench.pgm", board)
    _write_pgm(tmp_path / "blank.pgm", np.full((480, 640), 110, np.uint8))
    bench = (tmp_path / "bench.pgm", tmp_path / "bench.pgm")

    camera = softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                                    max_frames=4, frame_offset=0)
    table = softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                                   max_frames=4, frame_offset=0, bench_board=bench,
                                   chessboard="9x6", square_mm=20.0)
    assert table.summary["bench_board_rms_mm"] < 0.05
    np.testing.assert_allclose(table.summary["bench_board_origin_mm"], (-80.25, -50.25, 300.0),
                               atol=0.05)
    for name in ("red", "blue", "green"):
        np.testing.assert_allclose(table[f"{name}_X"], camera[f"{name}_X"] + 80.25, atol=0.05)
        np.testing.assert_allclose(table[f"{name}_Y"], camera[f"{name}_Y"] + 50.25, atol=0.05)
        np.testing.assert_allclose(table[f"{name}_Z"], 0.0, atol=0.05)
    for column in ("angle_deg", "radius_mm", "arc_length_mm", "tip_disp_mm"):
        np.testing.assert_array_equal(table[column], camera[column])

    with pytest.raises(softsight.InputError, match="blank.pgm: the 9x6 chessboard"):
        softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                               bench_board=(tmp_path / "blank.pgm", bench[1]),
                               chessboard="9x6", square_mm=20.0)
    with pytest.raises(softsight.InputError, match="does not say which board"):
        softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                               bench_board=bench)


def test_reference_plane_board_measures_against_the_bench_board(markers_yaml, stereo_yaml,
                                                                tmp_path):
    # The board of the test above, facing the rig like the bend: the bend lies in the board's
    # plane (0 degrees where the plane is defined). Without a bench board: refused.
    board = np.full((480, 640), 110, np.uint8)
    board[80:400, 100:540] = 230
    for i in range(10):
        for j in range(7):
            if (i + j) % 2 == 0:
                board[100 + 40 * j:140 + 40 * j, 120 + 40 * i:160 + 40 * i] = 25
    _write_pgm(tmp_path / "bench.pgm", board)
    bench = (tmp_path / "bench.pgm", tmp_path / "bench.pgm")
    table = softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                                   max_frames=6, frame_offset=0, bench_board=bench,
                                   chessboard="9x6", square_mm=20.0, reference_plane="board")
    out_of_plane = table["out_of_plane_deg"]
    defined = ~np.isnan(out_of_plane)
    assert defined.sum() >= 3
    np.testing.assert_allclose(out_of_plane[defined], 0.0, atol=0.05)
    with pytest.raises(softsight.InputError,
                       match="reference_plane board: the bench board's plane; give bench_board"):
        softsight.track_stereo("synth:bending", "synth:bending", markers_yaml, stereo_yaml,
                               reference_plane="board")


def _write_ppm(path: Path, bgr: np.ndarray) -> None:
    rgb = np.ascontiguousarray(bgr[:, :, ::-1])
    with open(path, "wb") as f:
        f.write(b"P6\n%d %d\n255\n" % (rgb.shape[1], rgb.shape[0]) + rgb.tobytes())


def _jerky_walk(count: int, seed: int = 3) -> list:
    """Scene frames of the bending scene visited at speeds that change every 2-7 frames: a bend
    that starts, stops and reverses (what the offset is found from)."""
    rng = np.random.default_rng(seed)
    frame, speed, left, walk = 60, 0, 0, []
    for _ in range(count):
        if left <= 0:
            speed = int(rng.choice([0, 0, 3, 6, 9, -4, -8]))
            left = int(rng.integers(2, 8))
        left -= 1
        frame = int(np.clip(frame + speed, 0, 299))
        walk.append(frame)
    return walk


def _two_videos(tmp_path: Path, walk: list, offset: int, count: int) -> tuple:
    """Two folders of the bending scene along `walk`: right frame i shows moment i, left frame i
    shows moment i + offset (the right camera started `offset` frames earlier)."""
    scene = softsight.sim.Scene("bending", frames=300)
    rendered: dict = {}
    folders = (tmp_path / "left", tmp_path / "right")
    for folder in folders:
        folder.mkdir()
    for i in range(count):
        for folder, moment in ((folders[0], i + offset), (folders[1], i)):
            frame = walk[moment]
            if frame not in rendered:
                rendered[frame] = scene.render(frame)[0]
            _write_ppm(folder / f"{i:03d}.ppm", rendered[frame])
    return folders


def test_without_frame_offset_the_offset_is_found_like_the_cli(markers_yaml, stereo_yaml,
                                                              tmp_path):
    left, right = _two_videos(tmp_path, _jerky_walk(41), 5, 36)
    table = softsight.track_stereo(left, right, markers_yaml, stereo_yaml)
    summary = table.summary
    assert summary["frame_offset"] == 5
    assert summary["frame_offset_method"] == "motion"
    assert summary["frame_offset_correlation"] > 0.99
    assert summary["frame_offset_next_correlation"] is None or (
        summary["frame_offset_next_correlation"] < summary["frame_offset_correlation"] - 0.15)
    assert summary["pairs"] == 31
    np.testing.assert_array_equal(table["right_frame"], table["frame"] + 5)
    for name in ("red", "blue", "green"):
        assert list(table[f"{name}_status"]) == ["found"] * 31
        np.testing.assert_allclose(table[f"{name}_Z"], 300.0, atol=1e-3)
    # The program says the same line; the offset given by hand gives the same columns.
    result = run_cli("track-stereo", "-c", str(markers_yaml), "--left", str(left), "--right",
                     str(right), "--stereo", str(stereo_yaml), "--csv", str(tmp_path / "a.csv"))
    assert summary["frame_offset_report"] in result.stdout
    given = softsight.track_stereo(left, right, markers_yaml, stereo_yaml, frame_offset=5)
    assert given.summary["frame_offset"] == 5
    assert given.summary["frame_offset_method"] == "given"
    assert given.summary["frame_offset_correlation"] is None
    assert given.summary["frame_offset_report"] is None
    for column in table:
        if column != "proc_ms":
            np.testing.assert_array_equal(table[column], given[column])


def test_a_repeating_motion_is_refused_with_the_clis_message(markers_yaml, stereo_yaml,
                                                            tmp_path):
    # A swing with a period of 8 frames: offsets 8 frames apart fit alike.
    walk = [int(round(150 + 60 * np.sin(2 * np.pi * t / 8))) for t in range(39)]
    left, right = _two_videos(tmp_path, walk, 3, 36)
    with pytest.raises(softsight.InputError) as error:
        softsight.track_stereo(left, right, markers_yaml, stereo_yaml)
    message = str(error.value)
    assert message.startswith("cannot find the frame offset between left and right within +-60 "
                              "frames: two offsets fit the motion alike")
    assert message.endswith("; pass frame_offset=N")
    cli = cli_error("track-stereo", "-c", str(markers_yaml), "--left", str(left), "--right",
                    str(right), "--stereo", str(stereo_yaml), "--csv", str(tmp_path / "r.csv"))
    assert cli == (message.replace("between left and right", "between --left and --right")
                   .replace("frame_offset=N", "--frame-offset N"))
    assert not (tmp_path / "r.csv").exists()
    # Given, the same videos track; a bad range names the argument.
    assert softsight.track_stereo(left, right, markers_yaml, stereo_yaml,
                                  frame_offset=3).summary["pairs"] == 33
    with pytest.raises(softsight.InputError, match="max_offset_frames: must be in"):
        softsight.track_stereo(left, right, markers_yaml, stereo_yaml, max_offset_frames=-1)


def _assert_rows_are_the_tables(rows: list, table) -> None:
    """Each row of frames_stereo holds the values of track_stereo's table row (proc_ms: each
    run's own clock)."""
    assert len(rows) == len(table["frame"])
    for i, row in enumerate(rows):
        assert list(row) == list(table), "the table's columns, in order"
        for name, value in row.items():
            if name == "proc_ms":
                continue
            expected = table[name][i]
            if isinstance(value, float) and np.isnan(value):
                assert np.isnan(expected), (i, name)
            else:
                assert value == expected, (i, name, value, expected)
                assert type(value) is type(expected.item()), (i, name)


def test_frames_stereo_gives_track_stereos_rows_pair_by_pair(markers_yaml, stereo_yaml, tmp_path):
    # The offset found as track_stereo finds it (+5), then exact 3D in every row.
    left, right = _two_videos(tmp_path, _jerky_walk(41), 5, 36)
    table = softsight.track_stereo(left, right, markers_yaml, stereo_yaml)
    rows = list(softsight.frames_stereo(left, right, markers_yaml, stereo_yaml))
    assert len(rows) == 31
    _assert_rows_are_the_tables(rows, table)
    for i, row in enumerate(rows):
        assert row["right_frame"] == row["frame"] + 5 == i + 5
        for name in ("red", "blue", "green"):
            assert row[f"{name}_status"] == "found"
            assert row[f"{name}_Z"] == pytest.approx(300.0, abs=1e-3)
    # max_frames and the progress callback: the pairs done, of max_frames.
    seen = []
    rows = list(softsight.frames_stereo(left, right, markers_yaml, stereo_yaml, 4, frame_offset=5,
                                        progress=lambda done, total: seen.append((done, total))))
    assert [r["frame"] for r in rows] == [0, 1, 2, 3]
    assert seen == [(1, 4), (2, 4), (3, 4), (4, 4)]


def _mpeg4_copy(video: Path, out: Path) -> Path:
    """The video as MPEG-4 (a key frame every 12th frame as OpenCV writes it)."""
    import cv2
    reader = cv2.VideoCapture(str(video))
    writer = cv2.VideoWriter(str(out), cv2.VideoWriter_fourcc(*"mp4v"), 30.0, (640, 480))
    while True:
        ok, image = reader.read()
        if not ok:
            break
        writer.write(image)
    writer.release()
    return out


def test_frames_stereo_of_predicted_videos_gives_the_rows_after_their_key_frame_check(
        bending_video, markers_yaml, stereo_yaml, tmp_path):
    # A pair of MPEG-4 videos: each row comes once both views' groups are checked, as
    # track_stereo's rows do, with the same values.
    left = _mpeg4_copy(bending_video, tmp_path / "left.mp4")
    table = softsight.track_stereo(left, bending_video, markers_yaml, stereo_yaml, frame_offset=0)
    rows = list(softsight.frames_stereo(left, bending_video, markers_yaml, stereo_yaml,
                                        frame_offset=0))
    assert len(rows) == 24
    _assert_rows_are_the_tables(rows, table)


@pytest.mark.skipif(not Path("/proc/self/fd").is_dir(), reason="needs Linux's /proc/self/fd")
def test_frames_stereo_lets_go_of_both_videos_and_says_the_clis_errors(
        bending_video, markers_yaml, stereo_yaml, tmp_path):
    from test_frames import open_files
    right = tmp_path / "right.avi"
    right.write_bytes(Path(bending_video).read_bytes())
    left, right = str(Path(bending_video).resolve()), str(right.resolve())
    gen = softsight.frames_stereo(left, right, markers_yaml, stereo_yaml, frame_offset=0)
    assert next(gen)["frame"] == 0
    assert left in open_files() and right in open_files()  # Held while the loop runs ...
    gen.close()
    assert left not in open_files() and right not in open_files()  # ... not after close().
    with pytest.raises(StopIteration):
        next(gen)
    for row in softsight.frames_stereo(left, right, markers_yaml, stereo_yaml, frame_offset=0):
        if row["frame"] == 2:
            break  # The generator is closed when it is dropped.
    del row
    assert left not in open_files() and right not in open_files()

    # Bad input: track_stereo's message, at the call.
    with pytest.raises(softsight.InputError) as at_call:
        softsight.frames_stereo(left, right, markers_yaml, tmp_path / "missing.yaml")
    with pytest.raises(softsight.InputError) as in_table:
        softsight.track_stereo(left, right, markers_yaml, tmp_path / "missing.yaml")
    assert str(at_call.value) == str(in_table.value)
    assert "missing.yaml: cannot open" in str(at_call.value)
    with pytest.raises(softsight.InputError, match="max_frames: -1 must be >= 0"):
        softsight.frames_stereo(left, right, markers_yaml, stereo_yaml, -1, frame_offset=0)
    # A left video cut mid-stream: the rows before it, then track_stereo's error.
    data = Path(bending_video).read_bytes()
    cut = tmp_path / "cut.avi"
    cut.write_bytes(data[: len(data) * 2 // 3])
    with pytest.raises(softsight.InputError) as in_table:
        softsight.track_stereo(cut, right, markers_yaml, stereo_yaml, frame_offset=0)
    got = []
    with pytest.raises(softsight.InputError) as in_loop:
        for row in softsight.frames_stereo(cut, right, markers_yaml, stereo_yaml, frame_offset=0):
            got.append(row["frame"])
    assert str(in_loop.value) == str(in_table.value)
    assert got == list(range(len(got))) and 0 < len(got) < 24
    assert str(cut.resolve()) not in open_files() and right not in open_files()
