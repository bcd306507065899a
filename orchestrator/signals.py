"""Stopping a match on SIGINT / SIGTERM: the signal sets an event that the runner watches, so
the match stops gracefully and everything is collected (``hlvs match``, ``hlvs scrimmage``, a
match in a pool, the scrimmage benchmark)."""

from __future__ import annotations

import logging
import os
import signal
import threading
from collections.abc import Iterator
from contextlib import contextmanager
from types import FrameType

log = logging.getLogger(__name__)


@contextmanager
def stop_on_signals() -> Iterator[threading.Event]:
    """SIGINT / SIGTERM set the event (the runner then stops and collects everything)."""
    event = threading.Event()
    owner = os.getpid()

    def handler(signum: int, frame: FrameType | None) -> None:
        if os.getpid() != owner:  # a forked helper (pyroute2's netns worker) inherits this
            os._exit(0)
        log.warning("received %s: stopping the match", signal.Signals(signum).name)
        event.set()

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield event
    finally:
        for sig, old in previous.items():
            signal.signal(sig, old)


__all__ = ["stop_on_signals"]
