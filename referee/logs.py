"""The referee's three logs.

* ``referee.log``: human, HLVS style ``[%08.3f|%08.3f] <Info|Warning|Error>: <message>`` =
  [real seconds since the referee started | simulated seconds], with a STATUS line (speed factor)
  every 20 s of wall time and ``FINAL SCORE: r-b`` at the end.
* ``referee_events.jsonl``: one JSON object per :class:`~referee.snapshot.RefereeEvent`.
* ``gamecontroller.log``: GameController state changes and packet counts.

Without a folder the lines only go to :mod:`logging`.
"""

from __future__ import annotations

import contextlib
import json
import logging
from pathlib import Path
from typing import TextIO

from contracts import files
from referee.clock import Clock
from referee.snapshot import RefereeEvent

logger = logging.getLogger(__name__)

HUMAN_LOG = files.REFEREE_LOG
EVENTS_LOG = files.REFEREE_EVENTS
GC_LOG = files.GAMECONTROLLER_LOG


def event_json(event: RefereeEvent) -> dict[str, object]:
    """A line of the events log: the event's record and its time in seconds."""
    return {"time": round(event.sim_time_ms / 1000.0, 3), **event.to_record()}


class RefereeLog:
    def __init__(self, *, clock: Clock, log_dir: Path | None = None) -> None:
        self._clock = clock
        self._start_s = clock.monotonic()
        self._files: dict[str, TextIO] = {}
        if log_dir is not None:
            log_dir.mkdir(parents=True, exist_ok=True)
            for name in (HUMAN_LOG, EVENTS_LOG, GC_LOG):
                self._files[name] = (log_dir / name).open("w", encoding="utf-8")

    def _prefix(self, sim_time_ms: int) -> str:
        real_s = self._clock.monotonic() - self._start_s
        return f"[{real_s:08.3f}|{sim_time_ms / 1000.0:08.3f}]"

    def _write(self, name: str, line: str) -> None:
        handle = self._files.get(name)
        if handle is not None:
            try:
                handle.write(line + "\n")
                handle.flush()
            except OSError as exc:  # the disk full: this log stops, the match goes on
                del self._files[name]
                with contextlib.suppress(OSError):
                    handle.close()
                logger.error("%s cut short: %s (the match went on)", handle.name,
                             exc.strerror or exc)

    def info(self, sim_time_ms: int, message: str) -> None:
        self._write(HUMAN_LOG, f"{self._prefix(sim_time_ms)} Info: {message}")
        logger.info("%s", message)

    def warning(self, sim_time_ms: int, message: str) -> None:
        self._write(HUMAN_LOG, f"{self._prefix(sim_time_ms)} Warning: {message}")
        logger.warning("%s", message)

    def error(self, sim_time_ms: int, message: str) -> None:
        self._write(HUMAN_LOG, f"{self._prefix(sim_time_ms)} Error: {message}")
        logger.error("%s", message)

    def event(self, event: RefereeEvent) -> None:
        self._write(EVENTS_LOG, json.dumps(event_json(event), sort_keys=True))

    def gamecontroller(self, sim_time_ms: int, message: str) -> None:
        self._write(GC_LOG, f"{self._prefix(sim_time_ms)} {message}")
        logger.debug("gamecontroller: %s", message)

    def close(self) -> None:
        for handle in self._files.values():
            with contextlib.suppress(OSError):
                handle.close()
        self._files.clear()
