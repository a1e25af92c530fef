"""Receive a run's results as they happen: the records ``--publish`` sends (docs/stream.md).

    from softsight import stream
    for record in stream.subscribe("tcp://localhost:5556"):
        print(record["frame"], record["angle_deg"])

Each record is a dict with the run's CSV columns and values (``None`` for an empty field);
iteration ends with the run (its "end" record). Needs pyzmq (Debian: python3-zmq).
"""

from __future__ import annotations

import json
import time
from typing import Any, Dict, Iterator, List, Optional

FORMAT = "softsight-stream"
VERSION = 1  # The format version this module reads (the hello's "version").

_POLL_MS = 100


def _zmq() -> Any:
    try:
        import zmq
    except ImportError as e:  # pragma: no cover - depends on the machine
        raise ImportError("softsight.stream needs pyzmq: apt install python3-zmq "
                          "(or pip install pyzmq)") from e
    return zmq


class Subscription:
    """A subscription to one topic of a run's stream; iterate it for the records (dicts).

    ``hello`` is the run's description once it arrived (source, config, config_digest,
    columns, markers, topics), ``end`` the run's end record (frames, stop_reason, sent,
    dropped), ``frame_gaps`` the frame numbers missing between records received.
    """

    def __init__(self, address: str, topic: str = "frame", timeout_s: Optional[float] = None,
                 count: Optional[int] = None) -> None:
        if not topic or " " in topic:
            raise ValueError(f"topic {topic!r}: give frame, measure or marker/NAME")
        if not (address.startswith("tcp://") or address.startswith("ipc://")):
            raise ValueError(f"{address}: not an endpoint; give tcp://HOST:PORT or ipc://PATH")
        zmq = _zmq()
        self.address = address
        self.topic = topic
        self.timeout_s = timeout_s
        self.count = count
        self.hello: Optional[Dict[str, Any]] = None
        self.end: Optional[Dict[str, Any]] = None
        self.frame_gaps = 0
        self.received = 0
        self._context = zmq.Context()
        self._socket = self._context.socket(zmq.SUB)
        self._socket.setsockopt(zmq.LINGER, 0)
        # Exact topics: "<topic> " with the space (ZeroMQ matches prefixes).
        for name in ("hello", topic, "end"):
            self._socket.setsockopt(zmq.SUBSCRIBE, (name + " ").encode())
        self._socket.connect(address)
        self._poller = zmq.Poller()
        self._poller.register(self._socket, zmq.POLLIN)
        self._last_frame: Optional[int] = None

    def __iter__(self) -> Iterator[Dict[str, Any]]:
        heard = time.monotonic()
        try:
            while self.count is None or self.received < self.count:
                if not self._poller.poll(_POLL_MS):
                    if self.timeout_s is not None and time.monotonic() - heard > self.timeout_s:
                        raise TimeoutError(f"{self.address}: nothing received for {self.timeout_s} s; "
                                           "is the run started with --publish at that endpoint?")
                    continue
                heard = time.monotonic()
                topic, _, body = self._socket.recv().decode().partition(" ")
                record = json.loads(body)
                if topic == "hello":
                    self._check(record)
                    self.hello = record
                elif topic == "end":
                    self.end = record
                    return
                elif topic == self.topic:
                    self.received += 1
                    frame = record.get("frame")
                    if isinstance(frame, int):
                        if self._last_frame is not None and frame > self._last_frame + 1:
                            self.frame_gaps += frame - self._last_frame - 1
                        self._last_frame = frame
                    yield record
        finally:
            self.close()

    def _check(self, hello: Dict[str, Any]) -> None:
        if hello.get("format") != FORMAT:
            raise ValueError(f"{self.address}: the hello is not {FORMAT}'s")
        if hello.get("version") != VERSION:
            raise ValueError(f"{self.address}: the publisher speaks {FORMAT} version "
                             f"{hello.get('version')}; this softsight reads version {VERSION}")

    def records(self) -> List[Dict[str, Any]]:
        """Every record until the run ends (or ``count``), as a list."""
        return list(self)

    def close(self) -> None:
        if not self._socket.closed:
            self._socket.close()
            self._context.term()

    def __enter__(self) -> "Subscription":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def subscribe(address: str, topic: str = "frame", timeout_s: Optional[float] = None,
              count: Optional[int] = None) -> Subscription:
    """Subscribe to a run's stream at ``address`` (its ``--publish``, e.g. tcp://localhost:5556).

    ``topic``: "frame" (every column), "measure" (the measurements), "marker/NAME" (one
    marker's columns). ``timeout_s``: raise TimeoutError after that long without any message.
    ``count``: stop after that many records. Iterate the result for dicts.
    """
    return Subscription(address, topic, timeout_s, count)


def to_dataframe(records: Any) -> Any:
    """The records (a Subscription, or a list of dicts) as a pandas DataFrame, columns in order."""
    try:
        import pandas
    except ImportError as e:
        raise ImportError("softsight.stream.to_dataframe needs pandas (apt install python3-pandas); "
                          "without it, Subscription.records() gives the same rows as a list of "
                          "dicts") from e
    rows = list(records)
    return pandas.DataFrame.from_records(rows, columns=list(rows[0].keys()) if rows else None)


def send_target(socket: Any, angle_deg: float) -> None:
    """Send one target to ``control --target-from`` on a pyzmq PUB socket the caller has bound."""
    socket.send(("target " + json.dumps({"angle_deg": float(angle_deg)})).encode())
