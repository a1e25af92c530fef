"""The geometry, the renderer with its truth and the calibration as functions on numpy arrays,
checked against exact truth."""

from __future__ import annotations

import math

import numpy as np
import pytest

import softsight
from softsight import calib, geometry, sim


def test_geometry_on_points_and_arrays():
    assert geometry.angle_deg((0, 0), (1, 0), (1, 1)) == pytest.approx(90.0)
    assert geometry.angle_deg((0, 0), (1, 0), (2, 0)) == pytest.approx(180.0)
    assert geometry.angle_deg((0, 0), (0, 0), (2, 0)) is None  # middle on base: undefined
    assert geometry.radius((0, 0), (1, 0), (2, 0)) is None      # straight: no radius
    assert geometry.arc_length((0, 0), (1, 0), (2, 0)) == pytest.approx(2.0)
    # Three points on a circle of radius 100, symmetric: eq. 8 and 9 give it back exactly.
    r, half = 100.0, math.radians(40)
    base = (r * math.sin(-half), r - r * math.cos(half))
    tip = (r * math.sin(half), r - r * math.cos(half))
    middle = (0.0, 0.0)
    assert geometry.radius(base, middle, tip) == pytest.approx(r, rel=1e-12)
    assert geometry.arc_length(base, middle, tip) == pytest.approx(r * 2 * half, rel=1e-12)
    assert geometry.circumradius(base, middle, tip) == pytest.approx(r, rel=1e-12)
    c = geometry.chord(base, tip)
    d = geometry.sagitta(base, middle, tip)
    assert geometry.radius_from_chord_sagitta(c, d) == pytest.approx(r, rel=1e-12)
    # Vectorised over (N, 2) arrays, NaN where undefined.
    angles = geometry.angle_deg(np.array([[0, 0], [0, 0]]), np.array([[1, 0], [0, 0]]),
                                np.array([[1, 1], [2, 0]]))
    assert angles[0] == pytest.approx(90.0) and math.isnan(angles[1])
    # The circle fit through points on an arc.
    t = np.linspace(0.2, 2.5, 7)
    points = np.stack([50 + 80 * np.cos(t), 40 + 80 * np.sin(t)], axis=1)
    fit = geometry.fit_circle(points)
    assert fit["radius"] == pytest.approx(80.0, rel=1e-9)
    assert fit["centre"] == pytest.approx((50.0, 40.0), abs=1e-7)
    assert geometry.arc_length_through_points(points) == pytest.approx(80 * 2.3, rel=1e-9)
    assert geometry.fit_circle([[0, 0], [1, 1], [2, 2]]) is None  # collinear
    with pytest.raises(ValueError):
        geometry.angle_deg((0, 0, 0), (1, 0), (1, 1))


def test_the_renderer_and_its_truth_against_the_session():
    # The first frames of the 300-frame sweep (in 8 frames the actuator would jump so far from
    # frame to frame that the session rightly calls the tip implausible).
    scene = sim.Scene("bending", frames=300, noise=2.0)
    assert (scene.frame_count, scene.size, scene.marker_names) == (300, (640, 480), ["red", "blue", "green"])
    session = softsight.Session({
        "markers": [{"name": "red", "hsv": {"h": [170, 10], "s": [80, 255], "v": [40, 255]}},
                    {"name": "blue", "hsv": {"h": [100, 130], "s": [80, 255], "v": [40, 255]}},
                    {"name": "green", "hsv": {"h": [45, 85], "s": [80, 255], "v": [40, 255]}}],
        "triple": ["red", "blue", "green"]})
    buffer = np.empty((480, 640, 3), np.uint8)
    for i in range(6):
        image, truth = scene.render(i, out=buffer)
        assert image is buffer or np.shares_memory(image, buffer)  # Drawn in place.
        r = session.process(image, truth["time_s"])
        for m in r.markers:
            t = truth["markers"][m.name]
            assert m.found and abs(m.x - t["x"]) < 0.3 and abs(m.y - t["y"]) < 0.3
        assert r.angle_deg == pytest.approx(truth["measurement"]["angle_deg"], abs=0.3)
        # The truth's measurements are the geometry of the true centroids.
        p = {name: (t["x"], t["y"]) for name, t in truth["markers"].items()}
        assert geometry.angle_deg(p["red"], p["blue"], p["green"]) == pytest.approx(
            truth["measurement"]["angle_deg"], abs=1e-9)
    # An `out` of another type is refused, not converted into a copy and left untouched.
    with pytest.raises(ValueError, match="out: expected a uint8 array, got float32"):
        scene.render(0, out=np.zeros((480, 640, 3), np.float32))
    plate = sim.Scene("plate", frames=3)
    image, truth = plate.render(2)
    assert image.shape == (480, 640, 3) and list(truth["markers"]) == plate.marker_names
    with pytest.raises(softsight.InputError, match="scene"):
        sim.Scene("nonsense")
    with pytest.raises(IndexError):
        scene.render(300)


def test_calibration_recovers_known_intrinsics():
    # A small camera (320x240, f = 300 px) keeps the rendering and the detection quick.
    k = np.array([[300.0, 0, 160], [0, 300.0, 120], [0, 0, 1]])
    distortion = [-0.2, 0.05, 0.0, 0.0]
    cal = calib.Calibrator(inner_corners=(9, 6), square_mm=25.0)
    tilts = [(0, 0, 0), (25, 0, 5), (-25, 0, -5), (0, 25, 10), (0, -25, -10), (20, 20, 0)]
    first_corners = None
    for i, (tx, ty, roll) in enumerate(tilts):
        image, corners = sim.render_chessboard(k, distortion, size=(320, 240), distance_mm=450, tilt_x_deg=tx, tilt_y_deg=ty,
                                               roll_deg=roll)
        assert image.shape == (240, 320) and image.dtype == np.uint8
        assert cal.add(f"view{i}", image)
        if first_corners is None:
            first_corners = (image, corners)
    found = calib.find_chessboard(first_corners[0], (9, 6))
    assert found.shape == (54, 2) and np.abs(found - first_corners[1]).max() < 0.2
    camera = cal.calibrate()
    assert camera["image_size"] == (320, 240) and camera["rms_px"] < 0.2
    assert camera["camera_matrix"][0, 0] == pytest.approx(300.0, rel=0.01)
    assert camera["camera_matrix"][1, 1] == pytest.approx(300.0, rel=0.01)
    # Undistorting the true corners of a board facing the camera makes its rows straight.
    straight = calib.undistort_points(first_corners[1], camera)
    row = straight[:9]
    slope, offset = np.polyfit(row[:, 0], row[:, 1], 1)
    assert np.abs(row[:, 1] - (slope * row[:, 0] + offset)).max() < 0.1
    plane = calib.plane_from_corners(straight, (9, 6), 25.0)
    assert plane["rms_mm"] < 0.1 and plane["mm_per_px"] == pytest.approx(450 / 300, rel=0.05)
    assert calib.scale_from_two_points((0, 0), (100, 0), 50.0) == pytest.approx(0.5)
    with pytest.raises(softsight.InputError):
        calib.Calibrator().calibrate()  # No views.


def test_a_bad_camera_dict_is_an_input_error_naming_the_key():
    good = {"image_size": (640, 480), "camera_matrix": np.array([[500.0, 0, 320], [0, 500.0, 240],
                                                                  [0, 0, 1]]),
            "distortion": (0.1, -0.05, 0.0, 0.0)}
    points = np.array([[100.0, 100.0], [320.0, 240.0]], np.float32)
    assert calib.undistort_points(points, good).shape == (2, 2)
    for broken, what in ((dict(good, distortion=(0.1, 0.2, 0.3)), "3 coefficients"),
                         ({k: v for k, v in good.items() if k != "distortion"}, "'distortion'"),
                         (dict(good, image_size=(0, 480)), "image_size"),
                         (dict(good, camera_matrix=np.zeros((3, 3))), "focal lengths")):
        with pytest.raises(softsight.InputError, match=what):
            calib.undistort_points(points, broken)


def test_softsight_batch_comes_with_the_package_without_importing_dask():
    # The stubs promise softsight.batch after `import softsight`; Dask is only imported when
    # track_many runs, so the import stays cheap.
    import subprocess
    import sys

    code = "import sys, softsight; print(callable(softsight.batch.track_many), 'distributed' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True,
                         timeout=60)
    assert out.stdout.split() == ["True", "False"]
