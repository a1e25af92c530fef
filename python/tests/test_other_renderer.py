"""Markers you can trust on footage softsight did not render.

A small renderer of its own (numpy and OpenCV's drawing, nothing of softsight's `sim`): a
constant-curvature band bending over time with three discs on it, drawn 4x supersampled. The truth
is each disc's centre, the marker's physical position, not the centroid of what is visible of it.
The scenes are the cases that once gave wrong positions: a box over most of a marker, the actuator
leaving through the frame's edge, a look-alike appearing beside a covered marker, the actuator
taken away in front of look-alikes; and cases that once lost markers for good or for most frames:
a camera bumped, a flickering light. Whatever is missed, nothing may be
reported found more than 3 px from a disc's centre, nor found while wholly hidden or gone.
"""

from __future__ import annotations

import math

import cv2
import numpy as np
import pytest

import softsight

W, H = 320, 240
FRAMES = 48
SS = 4  # Supersampling per side.
RADIUS = 7.0
COLOURS = {"red": (40, 40, 215), "blue": (210, 90, 30), "green": (60, 180, 40)}  # BGR
PLACES = {"red": 0.1, "blue": 0.5, "green": 0.9}  # Along the band, base to tip.
HSV = {"red": [170, 10], "blue": [100, 130], "green": [45, 85]}


def arc_point(base, length, bend_rad, s):
    """Point at arc length s along a band leaving `base` upwards and bending by `bend_rad`."""
    heading = -math.pi / 2
    k = bend_rad / length
    if abs(k) < 1e-9:
        return base[0] + s * math.cos(heading), base[1] + s * math.sin(heading)
    return (base[0] + (math.sin(heading + k * s) - math.sin(heading)) / k,
            base[1] - (math.cos(heading + k * s) - math.cos(heading)) / k)


def render(frame, shift_x=0.0, boxes=(), discs=(), present=True, seed=0):
    """One frame (BGR) and the truth: {marker: (x, y, visible fraction)}."""
    canvas = np.full((H * SS, W * SS, 3), 95, np.uint8)
    # A frame pixel's centre x is supersampled pixel (x + 0.5) * SS - 0.5 (INTER_AREA averages
    # SS x SS blocks); drawn with 4 fraction bits.
    up = lambda x, y: (int(round(((x + 0.5) * SS - 0.5) * 16)), int(round(((y + 0.5) * SS - 0.5) * 16)))
    for colour, x, y in discs:  # Look-alikes on the background.
        cv2.circle(canvas, up(x, y), int(RADIUS * SS * 16), COLOURS[colour], -1, cv2.LINE_AA, 4)
    truth = {}
    base = (W / 2 + shift_x, H - 20)
    bend = math.radians(150.0) * frame / (FRAMES - 1)
    if present:
        band = [up(*arc_point(base, 170.0, bend, s)) for s in np.linspace(0, 170.0, 60)]
        cv2.polylines(canvas, [np.array(band, np.int32)], False, (205, 205, 205), 22 * SS,
                      cv2.LINE_AA, 4)
        for name, place in PLACES.items():
            x, y = arc_point(base, 170.0, bend, place * 170.0)
            cv2.circle(canvas, up(x, y), int(RADIUS * SS * 16), COLOURS[name], -1, cv2.LINE_AA, 4)
            truth[name] = (x, y)
    for x0, y0, w, h in boxes:  # Grey covers over everything.
        cv2.rectangle(canvas, up(x0, y0), up(x0 + w, y0 + h), (120, 125, 130), -1, cv2.LINE_AA, 4)
    image = cv2.resize(canvas, (W, H), interpolation=cv2.INTER_AREA).astype(np.float32)
    image += np.random.default_rng(seed * 1000 + frame).normal(0, 2.0, image.shape)
    image = np.clip(image, 0, 255).astype(np.uint8)
    # Visible fraction of each disc: of its pixel centres, those inside the frame and under no box.
    visible = {}
    for name, (x, y) in truth.items():
        yy, xx = np.mgrid[int(y) - 9:int(y) + 10, int(x) - 9:int(x) + 10]
        disc = (xx - x) ** 2 + (yy - y) ** 2 <= RADIUS ** 2
        shown = disc & (xx >= 0) & (xx < W) & (yy >= 0) & (yy < H)
        for x0, y0, w, h in boxes:
            shown &= ~((xx >= x0) & (xx < x0 + w) & (yy >= y0) & (yy < y0 + h))
        visible[name] = (x, y, shown.sum() / disc.sum())
    return image, visible


def config(rois=None):
    markers = []
    for name in PLACES:
        marker = {"name": name, "hsv": {"h": HSV[name], "s": [80, 255], "v": [40, 255]}}
        if rois:
            marker["roi"] = rois[name]
        markers.append(marker)
    return {"markers": markers, "triple": list(PLACES)}


def track_and_score(tmp_path, frames, cfg):
    """Tracks the rendered frames; returns (misses while >= 90 % visible, wrong, false) and
    the positions found while wholly visible, as errors in px."""
    truths = []
    for i, (image, truth) in enumerate(frames):
        cv2.imwrite(str(tmp_path / ("f%04d.png" % i)), image)
        truths.append(truth)
    table = softsight.track(tmp_path / "f%04d.png", cfg)
    misses = wrong = false = 0
    errors = []
    for i, truth in enumerate(truths):
        for name in PLACES:
            found = bool(table[name + "_found"][i])
            if name not in truth or truth[name][2] == 0.0:
                false += found
                continue
            x, y, seen = truth[name]
            if not found:
                misses += seen >= 0.9
                continue
            error = math.hypot(table[name + "_x"][i] - x, table[name + "_y"][i] - y)
            wrong += error > 3.0
            if seen >= 0.999:
                errors.append(error)
    return misses, wrong, false, errors


def test_clean_scene_every_marker_at_its_discs_centre(tmp_path):
    frames = [render(f) for f in range(FRAMES)]
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config())
    assert (misses, wrong, false) == (0, 0, 0)
    assert len(errors) == 3 * FRAMES
    assert max(errors) < 0.3


def test_a_box_over_most_of_the_middle_marker(tmp_path):
    # From frame 12 to 30 a box follows the middle marker and hides all of it left of 2 px right
    # of its centre (about 60 %): what is visible has its centroid ~4 px from the disc's centre.
    frames = []
    for f in range(FRAMES):
        bx, by, _ = render(f)[1]["blue"]
        frames.append(render(f, boxes=[(bx - 58, by - 20, 60, 40)] if 12 <= f <= 30 else [],
                             seed=1))
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config())
    assert (wrong, false) == (0, 0)
    assert misses <= 3  # Found again once it is whole.
    assert max(errors) < 0.5


def test_the_actuator_leaving_through_the_frames_edge(tmp_path):
    frames = [render(f, shift_x=max(0.0, 7.0 * (f - 12)), seed=2) for f in range(FRAMES)]
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config())
    assert (wrong, false) == (0, 0)
    assert misses <= 9
    assert len(errors) >= 3 * 12


def test_a_look_alike_beside_a_covered_marker_is_not_taken_for_it(tmp_path):
    # Blue (found through a roi from frame 0) is covered from frame 16 to 32; a blue disc of its
    # size appears at frame 18, 25 px beside where blue was last seen (frame 15), and stays.
    _, start = render(0)
    rois = {n: [int(x - 2 * RADIUS), int(y - 2 * RADIUS), int(4 * RADIUS), int(4 * RADIUS)]
            for n, (x, y, _) in start.items()}
    last_x, last_y, _ = render(15)[1]["blue"]
    frames = []
    for f in range(FRAMES):
        bx, by, _ = render(f)[1]["blue"]
        cover = [(bx - 12, by - 12, 24, 24)] if 16 <= f <= 32 else []
        twin = [("blue", last_x - 25.0, last_y)] if f >= 18 else []
        frames.append(render(f, boxes=cover, discs=twin, seed=3))
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config(rois))
    assert (wrong, false) == (0, 0)
    assert max(errors) < 0.5


def test_the_actuator_taken_away_in_front_of_look_alikes(tmp_path):
    # No roi: a look-alike of each colour on the background makes every marker ambiguous while
    # the actuator is there; while it is away, the look-alikes stand alone.
    twins = [("red", 40.0, 40.0), ("blue", 280.0, 60.0), ("green", 50.0, 200.0)]
    frames = [render(f, discs=twins, present=not 16 <= f < 32, seed=4) for f in range(FRAMES)]
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config())
    assert (wrong, false) == (0, 0)


def test_markers_come_back_after_the_camera_jumps(tmp_path):
    # Rois from frame 0; at frame 16 the camera is bumped: everything moves 30 px right and
    # stays there. The markers are believed again within a frame or two (before, a roi bounded
    # every search after the jump was refused, and they were lost for good).
    _, start = render(0)
    rois = {n: [int(x - 2 * RADIUS), int(y - 2 * RADIUS), int(4 * RADIUS), int(4 * RADIUS)]
            for n, (x, y, _) in start.items()}
    frames = [render(f, shift_x=30.0 if f >= 16 else 0.0, seed=5) for f in range(FRAMES)]
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config(rois))
    assert (wrong, false) == (0, 0)
    assert misses <= 3 * 2
    assert max(errors) < 0.5


def test_a_flickering_light_loses_nothing(tmp_path):
    # Every frame from 8 on up to 40 % brighter or darker at random (a lamp on mains with a
    # camera out of step): a change of light, not another picture (before, 2 frames in 3 were
    # refused as "the whole frame changed"). A marker may be missed where the light halves from
    # one frame to the next: its learned colour refuses a blob at half its brightness.
    rng = np.random.default_rng(6)
    frames = []
    for f in range(FRAMES):
        image, truth = render(f, seed=6)
        gain = rng.uniform(0.6, 1.4) if f >= 8 else 1.0
        frames.append((np.clip(image.astype(np.float32) * gain, 0, 255).astype(np.uint8), truth))
    misses, wrong, false, errors = track_and_score(tmp_path, frames, config())
    assert (wrong, false) == (0, 0)
    assert misses <= 6
    assert max(errors) < 0.5

