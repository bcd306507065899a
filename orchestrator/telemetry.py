"""Match telemetry from the simulator (the only orchestrator module importing zenoh) and the
terminal view of a running match.

The simulator publishes ``hlvs/<match_id>/state`` (JSON, about 5 Hz) and ``hlvs/<match_id>/events``
(one RefereeEvent per message) on its control-network address; :class:`ZenohTelemetry` connects
there as a zenoh peer with multicast scouting and shared memory off and keeps the latest state.
:class:`LiveView` shows it with ``rich`` when stdout is a terminal, else as plain progress lines.
"""

from __future__ import annotations

import json
import logging
import sys
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol, TextIO, cast

import zenoh
from rich.console import Console
from rich.live import Live
from rich.table import Table

from contracts import ContractError, EventRecord, JSONObject, StateMessage
from contracts import telemetry as topics
from orchestrator.errors import InfrastructureError

log = logging.getLogger(__name__)


# Zenoh retries a connection 1 s after a failed one, then doubling up to 4 s: a subscriber that
# started before the simulator listened heard it up to 3 s late. In 5 of 13 runs of `hlvs bench
# bringup` (8 robots) the robots were all heard connected 2.5-2.7 s after their containers had
# started instead of 0.6-1.5 s (bring-up 5.8-7.0 s instead of 3.5-4.9; every robot had long
# connected); retrying every 0.1-0.5 s, 0 of 11 runs (0.43-1.03 s, bring-up 3.3-4.5 s)
CONNECT_RETRY = '{period_init_ms: 100, period_max_ms: 500, period_increase_factor: 1.5}'


def subscriber_config(endpoint: str) -> zenoh.Config:
    """A zenoh peer that connects to ``endpoint`` alone (multicast and gossip scouting and
    shared memory off), retrying every 0.1-0.5 s until it listens."""
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("scouting/gossip/enabled", "false")
    config.insert_json5("transport/shared_memory/enabled", "false")
    config.insert_json5("connect/endpoints", json.dumps([endpoint]))
    config.insert_json5("connect/retry", CONNECT_RETRY)
    return config


class TelemetrySource(Protocol):
    def latest(self) -> StateMessage | None: ...

    def last_message_at(self) -> float | None: ...  # time.monotonic() of the last message

    def events(self) -> list[EventRecord]: ...

    def close(self) -> None: ...


class ZenohTelemetry:
    """Subscribes to one match's telemetry at ``endpoint`` (e.g. ``tcp/10.213.7.2:7447``)."""

    def __init__(self, *, endpoint: str, match_id: str, clock: Callable[[], float] = time.monotonic
                 ) -> None:
        self._clock = clock
        self._lock = threading.Lock()
        self._latest: StateMessage | None = None
        self._change: StateMessage | None = None  # first message of a new game state, unread
        self._refused: set[str] = set()  # why state messages were refused (logged once each)
        self._last_at: float | None = None
        self._events: list[EventRecord] = []
        try:
            self._session = zenoh.open(subscriber_config(endpoint))
            self._subs = [
                self._session.declare_subscriber(
                    topics.topic(match_id, topics.STATE), self._on_state
                ),
                self._session.declare_subscriber(
                    topics.topic(match_id, topics.EVENTS), self._on_event
                ),
            ]
        except zenoh.ZError as exc:
            raise InfrastructureError(
                f"cannot subscribe to telemetry at {endpoint}: {exc}"
            ) from exc
        log.info("telemetry: subscribed to hlvs/%s/* at %s", match_id, endpoint)

    def _decode(self, sample: Any) -> JSONObject | None:
        try:
            value = json.loads(sample.payload.to_string())
        except ValueError:
            log.warning("telemetry: undecodable message on %s", sample.key_expr)
            return None
        return value if isinstance(value, dict) else None

    def _on_state(self, sample: Any) -> None:
        value = self._decode(sample)
        message = None
        if value is not None:
            try:
                message = StateMessage.from_dict(value, source=f"telemetry {sample.key_expr}")
            except ContractError as exc:
                if str(exc) not in self._refused:
                    self._refused.add(str(exc))
                    log.warning("%s (message ignored)", exc)
        with self._lock:
            self._last_at = self._clock()
            if message is not None:
                before = self._latest
                if before is None or (before.state, before.half) != (message.state, message.half):
                    self._change = message
                self._latest = message

    def _on_event(self, sample: Any) -> None:
        value = self._decode(sample)
        with self._lock:
            self._last_at = self._clock()
            if value is not None:  # a referee event as the simulator sends it
                self._events.append(cast("EventRecord", value))

    def latest(self) -> StateMessage | None:
        """The newest state message; but the first message of a new game state (or half) once,
        before newer ones, so a progress line shows how that state began (the full half at the
        first PLAYING), however fast the match runs between two reads."""
        with self._lock:
            change, self._change = self._change, None
            return change if change is not None else self._latest

    def last_message_at(self) -> float | None:
        with self._lock:
            return self._last_at

    def events(self) -> list[EventRecord]:
        with self._lock:
            return list(self._events)

    def close(self) -> None:
        for sub in self._subs:
            sub.undeclare()  # type: ignore[no-untyped-call]
        self._session.close()  # type: ignore[no-untyped-call]


def _seconds(value: float | None) -> str:
    return "?" if value is None else f"{value:.1f}"


def describe(state: StateMessage) -> str:
    """One progress line for a telemetry state."""
    score = state.score or {}
    secondary = state.secondary_state
    return (
        f"{state.state}"
        + (f"/{secondary}" if secondary and secondary != "NORMAL" else "")
        + f" half {state.half} {_seconds(state.secs_remaining)} s left"
        + f" score red {score.get('red', '?')} - {score.get('blue', '?')} blue"
        + f" sim {state.sim_time_ms / 1000:.1f} s"
        + f" rtf {state.real_time_factor:.2f}"
        + f" connected {','.join(state.connected) or '-'}"
    )



class LiveView:
    """Shows the match phase and the latest telemetry; ``update`` is cheap to call often.

    Without a terminal, a line is printed when the phase, game state, half, score or connected
    robots change, and at least every ``PLAIN_PERIOD_S`` seconds.
    """

    PLAIN_PERIOD_S = 10.0

    def __init__(self, *, match_id: str, stream: TextIO | None = None) -> None:
        self._stream = stream or sys.stdout
        self._match_id = match_id
        self._tty = self._stream.isatty()
        self._phase = "pending"
        self._last_key: object = None
        self._last_print = 0.0
        self._live: Live | None = None
        if self._tty:
            self._live = Live(self._table(None), console=Console(file=self._stream),
                              refresh_per_second=4, transient=False)
            self._live.start()

    def _table(self, state: StateMessage | None) -> Table:
        table = Table(title=f"match {self._match_id}", show_header=False)
        table.add_row("phase", self._phase)
        if state is not None:
            score = state.score or {}
            table.add_row("game", f"{state.state} ({state.secondary_state}), "
                          f"half {state.half}, {_seconds(state.secs_remaining)} s left")
            table.add_row("score", f"red {score.get('red')} - {score.get('blue')} blue")
            table.add_row("sim time", f"{state.sim_time_ms / 1000:.1f} s")
            table.add_row("real-time factor", f"{state.real_time_factor:.2f}")
            table.add_row("connected", ", ".join(state.connected) or "-")
        return table

    def update(self, *, phase: str, state: StateMessage | None) -> None:
        self._phase = phase
        if self._live is not None:
            self._live.update(self._table(state))
            return
        key = (phase, None if state is None else (
            state.state, state.half, json.dumps(state.score, sort_keys=True), state.connected))
        now = time.monotonic()
        if key != self._last_key or now - self._last_print >= self.PLAIN_PERIOD_S:
            line = f"[{phase}]" + (f" {describe(state)}" if state else "")
            self._stream.write(line + "\n")
            self._stream.flush()
            self._last_key = key
            self._last_print = now

    def close(self) -> None:
        if self._live is not None:
            self._live.stop()


__all__ = ["LiveView", "TelemetrySource", "ZenohTelemetry", "describe", "subscriber_config"]
