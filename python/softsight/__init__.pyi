# Type stubs for editors and type checkers: the public API of the softsight package.
import os
from typing import Any, Callable, Dict, Generator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import batch as batch  # Imported by __init__.py (Dask only when track_many runs).
from . import stream as stream  # Imported by __init__.py (pyzmq only when subscribe() runs).
from . import calib as calib
from . import geometry as geometry
from . import sim as sim

__version__: str
__license__: str

PathLike = Union[str, os.PathLike[str]]
ConfigSource = Union["Config", PathLike, Mapping[str, Any]]
# progress=: a callable progress(done, total) (total None when unknown), True (a tqdm bar, or a
# line on sys.stderr) or False/None (silent).
ProgressCallback = Callable[[int, Optional[int]], Any]
Progress = Union[bool, None, ProgressCallback]

class InputError(ValueError):
    """Bad input; the message is the CLI's one line naming the file, key or frame."""

class Config:
    """A checked tracking config (the YAML file's keys)."""
    @property
    def marker_names(self) -> List[str]: ...
    @property
    def methods(self) -> Dict[str, str]: ...
    @property
    def triple(self) -> Optional[Tuple[str, str, str]]: ...
    @property
    def chain(self) -> List[str]: ...
    @property
    def metric(self) -> bool: ...
    @property
    def columns(self) -> List[str]: ...
    @property
    def source(self) -> Union[str, Dict[str, Any]]: ...
    def save(self, path: PathLike) -> None: ...

def load_config(source: Union[PathLike, Mapping[str, Any]], method: Optional[str] = None) -> Config: ...

class Marker:
    """One marker in one frame; x, y are None when it was not found."""
    @property
    def name(self) -> str: ...
    @property
    def x(self) -> Optional[float]: ...
    @property
    def y(self) -> Optional[float]: ...
    @property
    def sigma_px(self) -> Optional[float]: ...
    @property
    def found(self) -> bool: ...
    @property
    def score(self) -> Optional[float]: ...
    @property
    def status(self) -> str: ...
    @property
    def track(self) -> str: ...
    @property
    def candidates(self) -> int: ...

class FrameResult:
    """One frame's markers and measurements (None where the CSV has an empty field)."""
    @property
    def frame(self) -> int: ...
    @property
    def time_s(self) -> float: ...
    @property
    def proc_ms(self) -> float: ...
    @property
    def markers(self) -> List[Marker]: ...
    def __getitem__(self, name: str) -> Marker: ...
    @property
    def measurement(self) -> Dict[str, Optional[float]]: ...
    @property
    def inner_angle_deg(self) -> List[Optional[float]]: ...
    @property
    def angle_deg(self) -> Optional[float]: ...
    @property
    def chord_px(self) -> Optional[float]: ...
    @property
    def sagitta_px(self) -> Optional[float]: ...
    @property
    def radius_px(self) -> Optional[float]: ...
    @property
    def arc_length_px(self) -> Optional[float]: ...
    @property
    def circumradius_px(self) -> Optional[float]: ...
    @property
    def tip_disp_px(self) -> Optional[float]: ...
    @property
    def chord_mm(self) -> Optional[float]: ...
    @property
    def sagitta_mm(self) -> Optional[float]: ...
    @property
    def radius_mm(self) -> Optional[float]: ...
    @property
    def arc_length_mm(self) -> Optional[float]: ...
    @property
    def tip_disp_mm(self) -> Optional[float]: ...

class Session:
    """Tracks a config's markers in frames your code supplies (read in place, GIL released)."""
    def __init__(self, config: ConfigSource, method: Optional[str] = None) -> None: ...
    def process(
        self, frame: npt.NDArray[np.uint8], time_s: float, index: Optional[int] = None
    ) -> FrameResult: ...
    @property
    def columns(self) -> List[str]: ...
    @property
    def next_index(self) -> int: ...
    def reset_tip_reference(self) -> None: ...
    def reselect(
        self,
        marker: str,
        frame: npt.NDArray[np.uint8],
        rect: Tuple[int, int, int, int],
        time_s: float = 0.0,
        index: Optional[int] = None,
    ) -> FrameResult: ...

class Table(Dict[str, npt.NDArray[Any]]):
    """A run's columns as numpy arrays, in the CSV's order."""
    summary: Optional[Dict[str, Any]]
    def __init__(
        self, columns: Mapping[str, npt.NDArray[Any]], summary: Optional[Dict[str, Any]] = None
    ) -> None: ...
    @property
    def rows(self) -> int: ...
    def to_pandas(self) -> Any: ...

def track(
    input: PathLike,
    config: ConfigSource,
    max_frames: Optional[int] = None,
    progress: Progress = False,
    *,
    csv: Optional[PathLike] = None,
    fps: float = 30.0,
    method: Optional[str] = None,
    hook: Optional[
        Callable[[npt.NDArray[np.uint8], FrameResult], Optional[Mapping[str, Optional[float]]]]
    ] = None,
    hook_columns: Optional[Sequence[str]] = None,
    hook_stop_on_error: bool = False,
) -> Table: ...
def track_stereo(
    left: PathLike,
    right: PathLike,
    config: ConfigSource,
    stereo: PathLike,
    max_frames: Optional[int] = None,
    *,
    right_config: Optional[ConfigSource] = None,
    frame_offset: Optional[int] = None,
    max_offset_frames: int = 60,
    max_epipolar_px: float = 2.0,
    reference_plane: str = "image",
    fps: float = 30.0,
    bench_board: Optional[Tuple[PathLike, PathLike]] = None,
    chessboard: Optional[str] = None,
    square_mm: Optional[float] = None,
) -> Table: ...
def frames(
    input: PathLike,
    config: ConfigSource,
    max_frames: Optional[int] = None,
    *,
    fps: float = 30.0,
    method: Optional[str] = None,
    progress: Progress = False,
) -> Generator[FrameResult, None, None]: ...
def frames_stereo(
    left: PathLike,
    right: PathLike,
    config: ConfigSource,
    stereo: PathLike,
    max_frames: Optional[int] = None,
    *,
    right_config: Optional[ConfigSource] = None,
    frame_offset: Optional[int] = None,
    max_offset_frames: int = 60,
    max_epipolar_px: float = 2.0,
    reference_plane: str = "image",
    fps: float = 30.0,
    bench_board: Optional[Tuple[PathLike, PathLike]] = None,
    chessboard: Optional[str] = None,
    square_mm: Optional[float] = None,
    progress: Progress = False,
) -> Generator[Dict[str, Union[int, float, str]], None, None]: ...
