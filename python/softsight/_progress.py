"""``progress=``: how far a run is, told through Python.

The C++ side only calls ``progress(done, total)``; what is drawn is drawn here, on whatever
``sys.stderr`` is at that moment. A line written to the process's fd 2 from C++ would bypass it:
a notebook and ``contextlib.redirect_stderr`` would see nothing.
"""

from __future__ import annotations

import sys
import time
from typing import Any, Callable, Optional, Union

__all__ = ["Progress", "ProgressCallback", "Reporter", "reporter"]

# progress(done, total): total is None when the input does not know its length.
ProgressCallback = Callable[[int, Optional[int]], Any]
Progress = Union[bool, None, ProgressCallback]


class Reporter:
    """A run's progress: called with (done, total), closed once when the run ends."""

    def __call__(self, done: int, total: Optional[int]) -> None:
        raise NotImplementedError

    def close(self) -> None:
        pass


class _Callback(Reporter):
    """The caller's own callable, called as it is."""

    def __init__(self, callback: ProgressCallback):
        self._callback = callback

    def __call__(self, done: int, total: Optional[int]) -> None:
        self._callback(done, total)


class _Line(Reporter):
    """progress=True without tqdm: "track: 12 / 300 frames" on sys.stderr, redrawn in place a few
    times a second (a line per frame would flood a log), and once more, finished, at the end."""

    def __init__(self, what: str, unit: str):
        self._what, self._unit = what, unit
        self._next_s = 0.0
        self._last: Optional[tuple] = None

    def _text(self) -> str:
        assert self._last is not None
        done, total = self._last
        of = "" if total is None else f" / {total}"
        return f"\r{self._what}: {done}{of} {self._unit}"

    def __call__(self, done: int, total: Optional[int]) -> None:
        self._last = (done, total)
        now = time.monotonic()
        if now < self._next_s:
            return
        self._next_s = now + 0.25
        sys.stderr.write(self._text())  # Looked up now: redirect_stderr and notebooks see it.
        sys.stderr.flush()

    def close(self) -> None:
        if self._last is not None:
            sys.stderr.write(self._text() + "\n")
            sys.stderr.flush()


class _Bar(Reporter):
    """progress=True with tqdm installed: a tqdm bar (tqdm.auto: a widget in a notebook), made at
    the first call, when the total is known."""

    def __init__(self, tqdm: Any, what: str, unit: str):
        self._tqdm, self._what, self._unit = tqdm, what, unit
        self._bar: Any = None

    def __call__(self, done: int, total: Optional[int]) -> None:
        if self._bar is None:
            self._bar = self._tqdm(total=total, desc=self._what, unit=f" {self._unit}",
                                   file=sys.stderr)
        self._bar.update(done - self._bar.n)

    def close(self) -> None:
        if self._bar is not None:
            self._bar.close()


def reporter(progress: Progress, what: str, unit: str) -> Optional[Reporter]:
    """The reporter for a ``progress=`` argument, None for no progress (False or None).

    ``True``: a tqdm bar when tqdm is importable, else a plain line on ``sys.stderr``; a callable:
    itself, called as ``progress(done, total)``. Anything else is a TypeError naming it.
    """
    if progress is None or progress is False:
        return None
    if progress is True:
        try:
            from tqdm.auto import tqdm
        except ImportError:
            return _Line(what, unit)
        return _Bar(tqdm, what, unit)
    if callable(progress):
        return _Callback(progress)
    raise TypeError(
        "progress: True (a tqdm bar, or a line on sys.stderr), False or None (silent), or a "
        f"callable progress(done, total), got {type(progress).__name__} {progress!r}"
    )

