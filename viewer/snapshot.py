"""One look at a running match's game state (score, clock, phase) through its telemetry.

Used by the tournament's overview (``hlvs schedule status``, the operator's page): subscribe to
the match's ``state`` key, keep the first message, close. None when the match has no telemetry
or sent nothing within the timeout.
"""

from __future__ import annotations

import json
import logging
import threading
from pathlib import Path
from typing import TYPE_CHECKING, cast

from viewer.errors import SourceError
from viewer.live import FeedFactory, LiveUnavailable
from viewer.sources import live_of

if TYPE_CHECKING:
    from tournament import LiveGame

log = logging.getLogger(__name__)

KEYS = ("state", "secondary_state", "half", "phase", "secs_remaining", "score", "sim_time_ms")


def game_snapshot(folder: Path, *, timeout_s: float = 1.0,
                  factory: FeedFactory | None = None) -> LiveGame | None:
    """The game state of the match playing in ``folder`` (its ``simulator/`` has the spec)."""
    try:
        live = live_of(folder)
    except SourceError:
        return None
    if live is None:
        return None
    if factory is None:
        from viewer.live import ZenohFeed

        factory = ZenohFeed
    got = threading.Event()
    found: LiveGame = {}

    def on_message(kind: str, payload: bytes) -> None:
        if kind != "state" or got.is_set():
            return
        try:
            data = json.loads(payload)
        except ValueError:
            return
        if isinstance(data, dict):
            # the state message's fields (contracts.telemetry.StateMessage)
            found.update(cast("LiveGame", {k: data[k] for k in KEYS if k in data}))
            got.set()

    try:
        feed = factory(live.endpoint, live.match_id, on_message)
    except LiveUnavailable as exc:
        log.debug("no snapshot of %s: %s", folder, exc)
        return None
    try:
        got.wait(timeout_s)
    finally:
        feed.close()
    return found or None
