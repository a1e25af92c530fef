# Type stubs: softsight.calib (compiled). A camera is a dict: {"image_size": (w, h),
# "camera_matrix": 3x3 array, "distortion": array}.
from typing import Any, Dict, Optional, Tuple

import numpy as np
import numpy.typing as npt

Camera = Dict[str, Any]

def find_chessboard(
    image: npt.NDArray[np.uint8], inner_corners: Tuple[int, int] = (9, 6)
) -> Optional[npt.NDArray[np.float32]]: ...

class Calibrator:
    def __init__(
        self,
        inner_corners: Tuple[int, int] = (9, 6),
        square_mm: float = 25.0,
        estimate_k3: bool = False,
        min_views: int = 3,
    ) -> None: ...
    def add(self, name: str, image: npt.NDArray[np.uint8]) -> bool: ...
    def calibrate(self) -> Camera: ...
    @property
    def views_found(self) -> int: ...
    @property
    def views_seen(self) -> int: ...

def load_camera(path: str) -> Camera: ...
def undistort_points(points: npt.ArrayLike, camera: Camera) -> npt.NDArray[np.float32]: ...
def undistort(image: npt.NDArray[np.uint8], camera: Camera) -> npt.NDArray[np.uint8]: ...
def plane_from_corners(
    corners: npt.ArrayLike, inner_corners: Tuple[int, int] = (9, 6), square_mm: float = 25.0
) -> Dict[str, Any]: ...
def scale_from_two_points(
    a: Tuple[float, float], b: Tuple[float, float], distance_mm: float
) -> float: ...
