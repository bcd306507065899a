"""Live telemetry of a match over zenoh (the only module of the simulator that imports zenoh).

Keys: ``hlvs/<match_id>/state`` (JSON, about 5 Hz: sim_time_ms, real_time_factor, state,
secondary_state, half, secs_remaining, score, connected, stepping, robots: each robot's latest
API traffic sample, see simulator.traffic), ``hlvs/<match_id>/events`` (one JSON referee event
per message), ``hlvs/<match_id>/poses`` (about 10 Hz, binary: u32 sim_time_ms, then float32
x y z qw qx qy qz of every body, little-endian) and ``hlvs/<match_id>/scene`` (the replay header
with its scene, JSON, every ``SCENE_PERIOD_S``, so that a viewer joining late can draw the
poses). The simulator listens on ``NetworkSpec.telemetry_listen`` (peer mode, multicast scouting
and shared memory off); viewers connect to it.
"""

from __future__ import annotations

import json
import logging
import time
from typing import TYPE_CHECKING, Any, Protocol

from contracts import EventRecord, JSONObject
from contracts import telemetry as topics
from simulator.errors import SimulatorError

if TYPE_CHECKING:
    from simulator.replay.format import HeaderRecord

log = logging.getLogger(__name__)

STATE_PERIOD_S = 0.2
POSES_PERIOD_S = 0.1
SCENE_PERIOD_S = 2.0


class TelemetryError(SimulatorError):
    def __init__(self, *, endpoint: str, reason: str) -> None:
        self.endpoint = endpoint
        self.reason = reason
        super().__init__(f"telemetry cannot listen on {endpoint}: {reason}")


class Telemetry(Protocol):
    def state(self, payload: JSONObject) -> None: ...

    def event(self, payload: EventRecord) -> None: ...

    def poses(self, payload: bytes) -> None: ...

    def close(self) -> None: ...


class NullTelemetry:
    """Telemetry switched off (no ``telemetry_listen``)."""

    def state(self, payload: JSONObject) -> None:
        return None

    def event(self, payload: EventRecord) -> None:
        return None

    def poses(self, payload: bytes) -> None:
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


class ZenohPublisher:
    """Publishes the match state and referee events on a zenoh session."""

    def __init__(
        self, *, match_id: str, listen: str, scene: HeaderRecord | None = None
    ) -> None:
        import zenoh

        try:
            self._session: Any = zenoh.open(zenoh_config(listen=listen))
        except zenoh.ZError as exc:
            raise TelemetryError(endpoint=listen, reason=str(exc)) from exc
        self._state: Any = self._session.declare_publisher(topics.topic(match_id, topics.STATE))
        self._events: Any = self._session.declare_publisher(topics.topic(match_id, topics.EVENTS))
        self._poses: Any = self._session.declare_publisher(topics.topic(match_id, topics.POSES))
        self._scene: Any = self._session.declare_publisher(topics.topic(match_id, topics.SCENE))
        self._scene_blob = json.dumps(scene, sort_keys=True) if scene is not None else None
        self._next_scene_s = 0.0
        log.info("telemetry on %s (keys hlvs/%s/state, hlvs/%s/events)", listen, match_id, match_id)

    def state(self, payload: JSONObject) -> None:
        self._state.put(json.dumps(payload, sort_keys=True))
        now = time.monotonic()
        if self._scene_blob is not None and now >= self._next_scene_s:
            self._next_scene_s = now + SCENE_PERIOD_S
            self._scene.put(self._scene_blob)

    def event(self, payload: EventRecord) -> None:
        self._events.put(json.dumps(payload, sort_keys=True, default=str))

    def poses(self, payload: bytes) -> None:
        self._poses.put(payload)

    def close(self) -> None:
        for publisher in (self._state, self._events, self._poses, self._scene):
            publisher.undeclare()
        self._session.close()


def open_telemetry(
    *, match_id: str, listen: str | None, scene: HeaderRecord | None = None
) -> Telemetry:
    if not listen:
        return NullTelemetry()
    return ZenohPublisher(match_id=match_id, listen=listen, scene=scene)
