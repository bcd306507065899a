"""Live telemetry of a match over zenoh (the only module of the simulator that imports zenoh).

Keys: ``hlvs/<match_id>/state`` (JSON, about 5 Hz: sim_time_ms, real_time_factor, state,
secondary_state, half, secs_remaining, score, connected, stepping) and ``hlvs/<match_id>/events``
(one JSON referee event per message). The simulator listens on ``NetworkSpec.telemetry_listen``
(peer mode, multicast scouting and shared memory off); viewers connect to it.
"""

from __future__ import annotations

import json
import logging
from typing import Any, Protocol

from simulator.errors import SimulatorError

log = logging.getLogger(__name__)

STATE_PERIOD_S = 0.2


class TelemetryError(SimulatorError):
    def __init__(self, *, endpoint: str, reason: str) -> None:
        self.endpoint = endpoint
        self.reason = reason
        super().__init__(f"telemetry cannot listen on {endpoint}: {reason}")


class Telemetry(Protocol):
    def state(self, payload: dict[str, Any]) -> None: ...

    def event(self, payload: dict[str, Any]) -> None: ...

    def close(self) -> None: ...


class NullTelemetry:
    """Telemetry switched off (no ``telemetry_listen``)."""

    def state(self, payload: dict[str, Any]) -> None:
        return None

    def event(self, payload: dict[str, Any]) -> None:
        return None

    def close(self) -> None:
        return None


def zenoh_config(
    *, listen: str | None = None, connect: str | None = None, mode: str = "peer"
) -> Any:
    import zenoh

    config = zenoh.Config()
    config.insert_json5("mode", json.dumps(mode))
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("transport/shared_memory/enabled", "false")
    if listen:
        config.insert_json5("listen/endpoints", json.dumps([listen]))
    if connect:
        config.insert_json5("connect/endpoints", json.dumps([connect]))
    return config


class ZenohTelemetry:
    """Publishes the match state and referee events on a zenoh session."""

    def __init__(self, *, match_id: str, listen: str) -> None:
        import zenoh

        try:
            self._session: Any = zenoh.open(zenoh_config(listen=listen))
        except zenoh.ZError as exc:
            raise TelemetryError(endpoint=listen, reason=str(exc)) from exc
        self._state: Any = self._session.declare_publisher(f"hlvs/{match_id}/state")
        self._events: Any = self._session.declare_publisher(f"hlvs/{match_id}/events")
        log.info("telemetry on %s (keys hlvs/%s/state, hlvs/%s/events)", listen, match_id, match_id)

    def state(self, payload: dict[str, Any]) -> None:
        self._state.put(json.dumps(payload, sort_keys=True))

    def event(self, payload: dict[str, Any]) -> None:
        self._events.put(json.dumps(payload, sort_keys=True, default=str))

    def close(self) -> None:
        self._state.undeclare()
        self._events.undeclare()
        self._session.close()


def open_telemetry(*, match_id: str, listen: str | None) -> Telemetry:
    if not listen:
        return NullTelemetry()
    return ZenohTelemetry(match_id=match_id, listen=listen)
