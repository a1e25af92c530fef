# Type stubs: softsight.batch.
import os
from typing import Any, Mapping, Optional, Sequence, Union

from . import Config, Progress, Table

def track_many(
    paths: Sequence[Union[str, os.PathLike[str]]],
    config: Union[Config, str, os.PathLike[str], Mapping[str, Any]],
    client: Any = None,
    out_dir: Union[str, os.PathLike[str]] = ".",
    *,
    max_frames: Optional[int] = None,
    fps: float = 30.0,
    method: Optional[str] = None,
    n_workers: int = 2,
    processes: bool = False,
    timeout_s: Optional[float] = None,
    progress: Progress = False,
) -> Table: ...
