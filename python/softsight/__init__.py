"""softsight: measure soft robots with a camera, from Python.

The C++ library's API with numpy at the edges (docs/python.md has a tour):

- ``load_config(path_or_dict)``: a checked tracking config (the YAML file's keys).
- ``Session(config).process(frame, time_s)``: track one frame your code supplies (a numpy
  uint8 HxWx3 BGR or HxW gray array, read in place); a FrameResult with every marker's
  ``x, y, found, score, status`` and the measurements (None where the CSV has an empty field).
- ``track(input, config)``: a whole video, image sequence or built-in scene ("synth:bending"),
  its CSV's columns as numpy arrays (a Table: a dict with ``to_pandas()``), the same rows as
  ``softsight track`` writes.
- ``frames(input, config)``: the same input and tracking, one FrameResult per frame, as a
  generator (``for r in softsight.frames("run.avi", config): ...``).
- ``track_stereo(left, right, config, stereo)``: two calibrated cameras, the columns of
  ``softsight track-stereo``; ``frames_stereo(...)``: the same run, one pair's row at a time.
- ``geometry``, ``calib``, ``sim``: the measurements, calibration and the renderer with its
  exact truth, on numpy arrays. ``batch.track_many``: many inputs on a Dask cluster.
  ``stream.subscribe(address)``: a run's results as they happen (its ``--publish``).

``progress=`` (track, frames, batch.track_many): a callable ``progress(done, total)``, True (a
tqdm bar when tqdm is installed, else a line on ``sys.stderr``) or False/None (silent, the
default).

Bad input raises ``InputError`` (a ValueError) with the CLI's one-line message.
"""

from __future__ import annotations

import os
import sys
from typing import Callable, Dict, Generator, Optional, Sequence, Tuple, Union

from . import _core, _progress
from ._core import Config, FrameResult, InputError, Marker, Session, calib, geometry, load_config, sim
from ._progress import Progress
from ._table import Table

# The compiled submodules import as softsight.geometry, softsight.sim, softsight.calib too.
for _name, _module in (("geometry", geometry), ("sim", sim), ("calib", calib)):
    sys.modules[f"{__name__}.{_name}"] = _module

__version__: str = _core.__version__
__license__: str = _core.__license__

__all__ = [
    "Config",
    "FrameResult",
    "InputError",
    "Marker",
    "Session",
    "Table",
    "batch",
    "calib",
    "frames",
    "frames_stereo",
    "geometry",
    "load_config",
    "sim",
    "stream",
    "track",
    "track_stereo",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


def track(
    input: PathLike,
    config: Union[Config, PathLike, dict],
    max_frames: Optional[int] = None,
    progress: Progress = False,
    *,
    csv: Optional[PathLike] = None,
    fps: float = 30.0,
    method: Optional[str] = None,
    hook: Optional[Callable[..., Optional[Dict[str, Optional[float]]]]] = None,
    hook_columns: Optional[Sequence[str]] = None,
    hook_stop_on_error: bool = False,
) -> Table:
    """Tracks the markers of ``config`` in ``input`` and returns the CSV's columns.

    ``input`` is what ``softsight track --input`` takes: a video file, a folder of images, a
    printf pattern ("frames/%04d.png", timed at ``fps``) or a built-in scene ("synth:bending",
    "synth:wedge1", "synth:wedge4", "synth:bench", "synth:plate"). ``config`` is a Config, a
    YAML path or a dict. ``max_frames`` stops early; ``csv`` also writes the CSV file, exactly as
    ``softsight track --csv`` does; ``method`` overrides every marker's method (``--method``).
    ``progress``: a callable ``progress(done, total)`` called after every frame (from the
    thread running track, holding the GIL: keep it cheap; ``total`` is None when the input does
    not know its length; an exception it raises ends the run and is raised here), True for a
    tqdm bar (a line on ``sys.stderr`` without tqdm), False or None for none (the default).

    ``hook``: a callable ``hook(frame, result)`` run on every frame (``frame`` a read-only
    numpy view of the BGR image, valid during the call: copy what you keep; ``result`` its
    FrameResult) that returns a dict of column name -> number (None or NaN: an empty field) or
    None; its columns are ``hook_columns`` (or the callable's ``columns`` attribute), after
    the tracking columns in the table and the CSV (``--hook``, docs/usage.md). A hook that
    raises has its traceback written to ``sys.stderr`` once, is switched off and the run goes
    on (``table.summary["hook_error"]`` holds the traceback); with ``hook_stop_on_error`` the
    run stops there and InputError is raised. A value that is not a number or a column not
    declared raises InputError.

    Returns a Table (a dict of numpy arrays, one per CSV column, in order: ``frame`` int64,
    ``<marker>_found`` bool, ``<marker>_status`` and ``<marker>_track`` str, the rest float64 with NaN for an empty
    field) holding the same values as the CLI's CSV; ``table.summary`` has the run's summary.

    Raises InputError with the CLI's message for a bad config, a missing or corrupt input or an
    unwritable CSV. When the input fails mid-run (a frame that does not decode) the error's
    ``table`` attribute holds the rows before it (the CSV keeps them too, as the CLI's does).
    The GIL is released while frames are processed; Ctrl-C stops the run.
    """
    if hook is not None:
        if not callable(hook):
            raise TypeError("hook: a callable hook(frame, result), got %s" % type(hook).__name__)
        if hook_columns is None:
            hook_columns = getattr(hook, "columns", None)
        if hook_columns is None:
            raise TypeError("hook_columns: the names of the values the hook returns, e.g. "
                            "hook_columns=[\"tip_speed\"] (or a `columns` attribute of the hook)")
        hook_columns = list(hook_columns) if isinstance(hook_columns, (list, tuple)) else hook_columns
    report = _progress.reporter(progress, "track", "frames")
    try:
        columns, summary = _core._track(
            input, config, max_frames, report, None if csv is None else os.fspath(csv), fps, method,
            hook, hook_columns, hook_stop_on_error
        )
    finally:
        if report is not None:
            report.close()
    table = Table(columns, summary)
    if summary["error"] is not None:
        error = InputError(summary["error"])
        error.table = table
        raise error
    return table


def track_stereo(
    left: PathLike,
    right: PathLike,
    config: Union[Config, PathLike, dict],
    stereo: PathLike,
    max_frames: Optional[int] = None,
    *,
    right_config: Union[Config, PathLike, dict, None] = None,
    frame_offset: Optional[int] = None,
    max_offset_frames: int = 60,
    max_epipolar_px: float = 2.0,
    reference_plane: str = "image",
    fps: float = 30.0,
    bench_board: Optional[Tuple[PathLike, PathLike]] = None,
    chessboard: Optional[str] = None,
    square_mm: Optional[float] = None,
) -> Table:
    """Tracks the markers of ``config`` in two views of a calibrated pair of cameras and returns
    the columns ``softsight track-stereo`` writes (docs/stereo.md).

    ``left`` and ``right`` are videos, folders of images or printf patterns; ``stereo`` is the
    file of ``softsight calibrate --left ... --right ...``. Right frame ``i + frame_offset`` is
    paired with left frame ``i``; ``frame_offset=None`` (the default) finds the offset as
    ``track-stereo`` does without ``--frame-offset``: from a flash, else the motion, within
    ``max_offset_frames`` either way (both inputs are read once more for it), and raises
    InputError ("cannot find the frame offset between left and right ...; pass frame_offset=N")
    when it is not clear (a repeating motion, a still scene). ``right_config``: the right view's
    markers when they need other colours or rois (the same names). A marker has ``<m>_X/_Y/_Z``
    (mm, the first camera's frame) only when both views found it and the pair passed the
    epipolar check (``max_epipolar_px``); ``<m>_status`` says why not. ``reference_plane``:
    "image", "first" or "board" (what the out-of-plane angle is measured against; "board" needs
    ``bench_board``). ``bench_board=(left_image, right_image)``: one pair of pictures of the
    chessboard lying on the bench; ``<m>_X/_Y/_Z`` and ``plane_n*`` are then in the board's frame
    (``--bench-board``; the board from ``chessboard="9x6"`` and ``square_mm``, else the stereo
    file's; ``table.summary`` adds ``bench_board_rms_mm`` and ``bench_board_origin_mm``).

    Returns a Table (``frame`` and ``right_frame`` int64, ``<m>_status`` str, the rest float64,
    NaN for an empty field); ``table.summary`` has ``pairs``, ``found`` and ``epipolar`` (per
    marker), ``baseline_mm``, ``frame_offset`` (the offset used), ``frame_offset_method``
    ("given", "flash" or "motion"), ``frame_offset_correlation`` and
    ``frame_offset_next_correlation`` (the motion's r at the offset and at the next best peak, else
    None) and ``frame_offset_report`` (the CLI's line, None when given). Raises InputError with
    the CLI's message for bad input.
    """
    columns, summary = _core._track_stereo(
        left, right, config, stereo, max_frames, right_config, frame_offset, max_offset_frames,
        max_epipolar_px, reference_plane, fps, bench_board, chessboard, square_mm
    )
    return Table(columns, summary)


def frames(
    input: PathLike,
    config: Union[Config, PathLike, dict],
    max_frames: Optional[int] = None,
    *,
    fps: float = 30.0,
    method: Optional[str] = None,
    progress: Progress = False,
) -> Generator[FrameResult, None, None]:
    """Tracks ``input`` frame by frame: a generator of FrameResult, one per frame, in order.

    ``input``, ``config``, ``max_frames``, ``fps``, ``method`` and ``progress`` are ``track``'s:
    the frames come from the library's own reader (videos, image sequences, folders, built-in
    scenes, with the same decode rules and checks), and each result holds the values of the row
    ``track`` gives for that frame (``result.frame``, ``result.time_s``, every marker and
    measurement), as ``Session.process`` returns them. The GIL is released while a frame is read
    and tracked.

    The input is opened here: a bad config or a missing input raises InputError at the call. A
    frame that does not decode raises InputError from the loop, after the frames before it. The
    input is let go of when the loop ends, breaks (the generator is closed when it is dropped)
    or ``close()`` is called on the generator.
    """
    stream = _core._FrameStream(input, config, max_frames, fps, method)
    return _frames(stream, _progress.reporter(progress, "frames", "frames"))


def frames_stereo(
    left: PathLike,
    right: PathLike,
    config: Union[Config, PathLike, dict],
    stereo: PathLike,
    max_frames: Optional[int] = None,
    *,
    right_config: Union[Config, PathLike, dict, None] = None,
    frame_offset: Optional[int] = None,
    max_offset_frames: int = 60,
    max_epipolar_px: float = 2.0,
    reference_plane: str = "image",
    fps: float = 30.0,
    bench_board: Optional[Tuple[PathLike, PathLike]] = None,
    chessboard: Optional[str] = None,
    square_mm: Optional[float] = None,
    progress: Progress = False,
) -> Generator[Dict[str, Union[int, float, str]], None, None]:
    """Tracks a calibrated pair of cameras pair by pair: a generator of each pair's row, in order.

    The arguments are ``track_stereo``'s (the frame offset is found the same way when not given,
    reading both inputs once more first), and ``progress`` is ``frames``'s (``total`` is
    ``max_frames``, None without it: a pair does not know its length). Each row is a dict of
    column name -> value holding exactly what ``track_stereo``'s table has for that pair:
    ``frame`` and ``right_frame`` int, ``<m>_status`` str, the rest float (NaN for an empty
    field), in the columns' order. The pairs run through the same run loop as ``track_stereo``
    and ``softsight track-stereo``, so a pair of predicted videos' (MPEG-4, H.264) rows come
    once each view's next key frame has been tracked (a marker either view's decoder silently
    damaged is then not found in 3D), and the GIL is released while pairs are read and tracked.

    A bad config, calibration or input raises InputError (the CLI's message) when
    ``frames_stereo`` is called; a frame that does not decode raises it from the loop, after the
    rows before it. Both inputs are let go of when the loop ends, ``break``s (the generator is
    closed when it is dropped) or ``close()`` is called on the generator.
    """
    stream = _core._StereoFrameStream(
        left, right, config, stereo, max_frames, right_config, frame_offset, max_offset_frames,
        max_epipolar_px, reference_plane, fps, bench_board, chessboard, square_mm
    )
    return _frames(stream, _progress.reporter(progress, "frames_stereo", "pairs"))


def _frames(stream: "_core._FrameStream", report: Optional[_progress.Reporter]) -> Generator[FrameResult, None, None]:
    try:
        while True:
            result = stream.next()
            if result is None:
                return
            if report is not None:
                report(stream.done, stream.total)
            yield result
    finally:  # The end, an error, or close(): the video is released now, not at garbage collection.
        stream.close()
        if report is not None:
            report.close()


# Imported with the package so ``softsight.batch`` is there after ``import softsight``, as the
# stubs say; cheap, since Dask itself is only imported when track_many runs. Last: it imports
# track from this module.
from . import batch  # noqa: E402
from . import stream  # noqa: E402  (pyzmq only when subscribe() runs)
