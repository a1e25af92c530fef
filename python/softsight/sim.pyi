# Type stubs: softsight.sim (compiled): the synthetic renderer with its exact truth.
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

class Scene:
    def __init__(
        self,
        name: str = "bending",
        *,
        frames: Optional[int] = None,
        size: Optional[Tuple[int, int]] = None,
        fps: Optional[float] = None,
        max_bend_deg: Optional[float] = None,
        oscillate: bool = False,
        seed: Optional[int] = None,
        noise: float = 0.0,
        blur: float = 0.0,
        gain: Tuple[float, float] = (1.0, 1.0),
        noise_seed: int = 7,
        supersample: int = 4,
    ) -> None: ...
    def render(
        self, index: int, out: Optional[npt.NDArray[np.uint8]] = None
    ) -> Tuple[npt.NDArray[np.uint8], Dict[str, Any]]: ...
    @property
    def frame_count(self) -> int: ...
    @property
    def fps(self) -> float: ...
    @property
    def name(self) -> str: ...
    @property
    def size(self) -> Tuple[int, int]: ...
    @property
    def marker_names(self) -> List[str]: ...
    def __len__(self) -> int: ...

def render_chessboard(
    camera_matrix: npt.ArrayLike,
    distortion: Sequence[float] = (),
    *,
    inner_corners: Tuple[int, int] = (9, 6),
    square_mm: float = 25.0,
    size: Tuple[int, int] = (640, 480),
    distance_mm: float = 500.0,
    tilt_x_deg: float = 0.0,
    tilt_y_deg: float = 0.0,
    roll_deg: float = 0.0,
    noise: float = 0.0,
) -> Tuple[npt.NDArray[np.uint8], npt.NDArray[np.float32]]: ...
