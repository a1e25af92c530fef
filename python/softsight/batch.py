"""Many inputs on a Dask cluster: ``track_many``.

Each input is one task running ``softsight.track`` on a worker (the GIL is released while it
tracks), writing its own CSV; the caller gets a summary table with one row per input. A failing
input (missing, corrupt, a frame that does not decode) is a row with ``ok`` False and the CLI's
error message; the others carry on. Needs Dask (Debian: python3-dask, python3-distributed).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np

from . import InputError, _progress, load_config, track
from ._progress import Progress
from ._table import Table

__all__ = ["track_many"]

PathLike = Union[str, "os.PathLike[str]"]


def _csv_names(paths: Sequence[str], out_dir: Path) -> List[str]:
    """One CSV per input, named after it; a name already taken gets -1, -2, ... (as the CLI's
    ``softsight track -i A -i B -o FOLDER/`` names them: app/track_many.h)."""
    taken: set = set()
    names = []
    for path in paths:
        stem = Path(path).stem if not path.startswith("synth:") else path.replace(":", "_")
        stem = stem.replace("%", "") or "input"
        name, n = f"{stem}.csv", 0
        while name in taken:
            n += 1
            name = f"{stem}-{n}.csv"
        taken.add(name)
        names.append(str(out_dir / name))
    return names


def _track_one(path: str, config, csv: str, max_frames: Optional[int], fps: float,
               method: Optional[str]) -> Dict[str, Any]:
    """One input, on a worker: its summary row (never raises for bad input)."""
    try:
        from distributed import get_worker

        worker = get_worker().address
    except (ImportError, ValueError):
        worker = ""
    row: Dict[str, Any] = {"input": path, "csv": csv, "worker": worker}
    try:
        table = track(path, config, max_frames, csv=csv, fps=fps, method=method)
        row.update(ok=True, error="", summary=table.summary)
    except InputError as error:
        table = getattr(error, "table", None)
        row.update(ok=False, error=str(error), summary=None if table is None else table.summary)
    return row


def _importing_the_main_script() -> bool:
    """Whether this process is a spawned worker still importing the caller's script (Python's
    multiprocessing marks that phase, and refuses to start processes during it, too)."""
    import multiprocessing

    return bool(getattr(multiprocessing.current_process(), "_inheriting", False))


def _unguarded_main_line() -> Optional[int]:
    """The line of the caller's script that calls track_many at import time, outside an
    ``if __name__ == "__main__":`` block; None when the call is guarded or comes from no script
    (a notebook, ``python -c``, a thread). Such a line runs again in every worker that Dask's
    process workers import the script into."""
    import ast
    import inspect

    main = sys.modules.get("__main__")
    path = getattr(main, "__file__", None)
    frame = inspect.currentframe()
    line = None
    while frame is not None:  # The script's own top-level frame, if it is on the stack.
        if frame.f_code.co_name == "<module>" and frame.f_globals.get("__name__") == "__main__":
            line = frame.f_lineno
        frame = frame.f_back
    if line is None or not path:
        return None
    try:
        tree = ast.parse(Path(path).read_text())
    except (OSError, SyntaxError, ValueError):
        return None  # Not readable as Python: nothing to say about it.

    def is_main_guard(node: ast.AST) -> bool:
        names = {n.id for n in ast.walk(node) if isinstance(n, ast.Name)}
        texts = {n.value for n in ast.walk(node) if isinstance(n, ast.Constant)}
        return "__name__" in names and "__main__" in texts

    for node in ast.walk(tree):
        if isinstance(node, ast.If) and is_main_guard(node.test):
            end = getattr(node, "end_lineno", None) or node.lineno
            if node.lineno <= line <= end:
                return None
    return line


def _failed(path: str, csv: str, error: BaseException) -> Dict[str, Any]:
    """The row of an input whose task itself failed (a worker lost, a timeout)."""
    text = str(error) or type(error).__name__
    return {"input": path, "csv": csv, "worker": "", "ok": False,
            "error": f"{type(error).__name__}: {text}", "summary": None}


def _summary_table(rows: List[Dict[str, Any]], markers: List[str]) -> Table:
    def summary(row, key, default):
        s = row["summary"]
        return default if s is None or s.get(key) is None else s[key]

    columns: Dict[str, np.ndarray] = {
        "input": np.array([r["input"] for r in rows], dtype="U"),
        "csv": np.array([r["csv"] for r in rows], dtype="U"),
        "ok": np.array([r["ok"] for r in rows], dtype=bool),
        "frames": np.array([summary(r, "frames", 0) for r in rows], dtype=np.int64),
        "stop_reason": np.array([summary(r, "stop_reason", "error") for r in rows], dtype="U"),
        "error": np.array([r["error"] for r in rows], dtype="U"),
    }
    for name in markers:
        columns[f"found_{name}"] = np.array(
            [summary(r, "found_rate", {}).get(name, np.nan) for r in rows], dtype=np.float64)
    columns["measured"] = np.array([summary(r, "measured", 0) for r in rows], dtype=np.int64)
    for key in ("proc_ms_median", "proc_ms_p99", "wall_s"):
        columns[key] = np.array([summary(r, key, np.nan) for r in rows], dtype=np.float64)
    columns["worker"] = np.array([r["worker"] for r in rows], dtype="U")
    return Table(columns)


def track_many(
    paths: Sequence[PathLike],
    config,
    client=None,
    out_dir: PathLike = ".",
    *,
    max_frames: Optional[int] = None,
    fps: float = 30.0,
    method: Optional[str] = None,
    n_workers: int = 2,
    processes: bool = False,
    timeout_s: Optional[float] = None,
    progress: Progress = False,
) -> Table:
    """Tracks every input of ``paths`` on a Dask cluster; one CSV per input in ``out_dir``.

    ``config`` is a Config, a YAML path or a dict, checked here first (a bad config raises
    InputError before anything runs; workers reload it from its path or dict, so a path must be
    readable on the workers, as the inputs must). ``client`` is a ``distributed.Client``, a
    scheduler address ("tcp://host:8786"), or None for a LocalCluster of ``n_workers`` workers
    (threads in this process unless ``processes``; closed again at the end). ``max_frames``,
    ``fps`` and ``method`` are ``track``'s. ``timeout_s`` bounds the wait for each input.
    ``processes=True`` starts the workers as new interpreters that import the calling script
    again: that script must start its work under ``if __name__ == "__main__":`` (docs/python.md).
    ``progress``: ``track``'s, counting inputs: ``progress(done, total)`` in this process as
    each input's row comes in (in input order), True for a bar or line, False/None for none.

    Returns a Table (``to_pandas()`` for a DataFrame) with one row per input, in order: input,
    csv, ok, frames, stop_reason, error (the CLI's one-line message; "" when ok), found_<marker>
    (found rate), measured, proc_ms_median, proc_ms_p99, wall_s, worker. An input that fails
    is a row with ok False; the others run on. Each CSV holds the rows ``softsight track``
    writes (a failed input's CSV keeps the rows before its error).
    """
    try:
        from distributed import Client, LocalCluster
    except ImportError as error:
        raise ImportError(
            "softsight.batch.track_many needs Dask's distributed scheduler (Debian: apt install "
            "python3-dask python3-distributed; or pip install 'dask[distributed]')"
        ) from error
    checked = load_config(config, method=method)  # A bad config fails here, once.
    if client is None and processes:  # Before anything is made or started.
        # A script that calls track_many at import time, without the guard: each worker imports
        # it again, starts a cluster of its own, dies and is restarted by Dask, over and over.
        # Refused before any process starts (and, should a worker get here, there too).
        guard = ("start the work under `if __name__ == \"__main__\":` (docs/python.md, 'Many "
                 "videos on a Dask cluster')")
        line = _unguarded_main_line()
        if line is not None:
            raise RuntimeError(
                f"softsight.batch.track_many(processes=True): {sys.modules['__main__'].__file__} "
                f"line {line} calls it when the script is imported, and every worker process "
                f"imports it again: {guard}")
        if _importing_the_main_script():
            raise RuntimeError(
                "softsight.batch.track_many(processes=True) ran while a worker process was "
                f"importing the calling script: {guard}")
    report = _progress.reporter(progress, "track_many", "inputs")  # A bad value too.
    inputs = [os.fspath(p) for p in paths]
    out = Path(os.fspath(out_dir))
    out.mkdir(parents=True, exist_ok=True)
    csvs = _csv_names(inputs, out)

    own_cluster = own_client = None
    if client is None:
        own_cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=processes,
                                   dashboard_address=None)
        client = own_client = Client(own_cluster)
    elif isinstance(client, str):
        client = own_client = Client(client)
    try:
        futures = [
            client.submit(_track_one, path, checked, csv, max_frames, fps, None, pure=False)
            for path, csv in zip(inputs, csvs)
        ]
        rows = []
        for path, csv, future in zip(inputs, csvs, futures):
            try:
                rows.append(future.result(timeout=timeout_s))
            except Exception as error:  # A lost worker, a timeout: this input failed.
                future.cancel()
                rows.append(_failed(path, csv, error))
            if report is not None:
                report(len(rows), len(futures))
    finally:
        if report is not None:
            report.close()
        if own_client is not None:
            own_client.close()
        if own_cluster is not None:
            own_cluster.close()
    return _summary_table(rows, checked.marker_names)
