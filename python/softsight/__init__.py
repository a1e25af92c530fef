"""softsight: measure soft robots with a camera, from Python.

The C++ library's API with numpy at the edges (docs/python.md has a tour):

- ``load_config(path_or_dict)``: a checked tracking config (the YAML file's keys).
- ``Session(config).process(frame, time_s)``: track one frame your code supplies (a numpy
  uint8 HxWx3 BGR or HxW gray array, read in place); a FrameResult with every marker's
  ``x, y, found, score, status`` and the measurements (None where the CSV has an empty field).
- ``track(input, config)``: a whole video, image sequence or built-in scene ("synth:bending"),
  its CSV's columns as numpy arrays (a Table: a dict with ``to_pandas()``), the same rows as
  ``softsight track`` writes.
- ``geometry``, ``calib``, ``sim``: the measurements, calibration and the renderer with its
  exact truth, on numpy arrays. ``batch.track_many``: many inputs on a Dask cluster.

Bad input raises ``InputError`` (a ValueError) with the CLI's one-line message.
"""

from __future__ import annotations

import os
import sys
from typing import Optional, Union

from . import _core
from ._core import Config, FrameResult, InputError, Marker, Session, calib, geometry, load_config, sim
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
    "calib",
    "geometry",
    "load_config",
    "sim",
    "track",
    "__version__",
]

PathLike = Union[str, "os.PathLike[str]"]


def track(
    input: PathLike,
    config: Union[Config, PathLike, dict],
    max_frames: Optional[int] = None,
    progress: bool = False,
    *,
    csv: Optional[PathLike] = None,
    fps: float = 30.0,
    method: Optional[str] = None,
) -> Table:
    """Tracks the markers of ``config`` in ``input`` and returns the CSV's columns.

    ``input`` is what ``softsight track --input`` takes: a video file, a folder of images, a
    printf pattern ("frames/%04d.png", timed at ``fps``) or a built-in scene ("synth:bending",
    "synth:wedge1", "synth:wedge4", "synth:bench", "synth:plate"). ``config`` is a Config, a
    YAML path or a dict. ``max_frames`` stops early; ``progress`` prints a progress line on
    stderr; ``csv`` also writes the CSV file, exactly as ``softsight track --csv`` does;
    ``method`` overrides every marker's method (``--method``).

    Returns a Table (a dict of numpy arrays, one per CSV column, in order: ``frame`` int64,
    ``<marker>_found`` bool, ``<marker>_status`` str, the rest float64 with NaN for an empty
    field) holding the same values as the CLI's CSV; ``table.summary`` has the run's summary.

    Raises InputError with the CLI's message for a bad config, a missing or corrupt input or an
    unwritable CSV. When the input fails mid-run (a frame that does not decode) the error's
    ``table`` attribute holds the rows before it (the CSV keeps them too, as the CLI's does).
    The GIL is released while frames are processed; Ctrl-C stops the run.
    """
    columns, summary = _core._track(
        input, config, max_frames, progress, None if csv is None else os.fspath(csv), fps, method
    )
    table = Table(columns, summary)
    if summary["error"] is not None:
        error = InputError(summary["error"])
        error.table = table
        raise error
    return table
