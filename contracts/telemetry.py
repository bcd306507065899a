"""Telemetry keys (zenoh) the simulator publishes and the orchestrator and viewer subscribe to.

``hlvs/<match_id>/state``: JSON, about 5 Hz (sim_time_ms, real_time_factor, state,
secondary_state, half, secs_remaining, score, connected, stepping, robots);
``hlvs/<match_id>/events``: one JSON referee event per message;
``hlvs/<match_id>/poses``: about 10 Hz, binary (u32 sim_time_ms, then float32 x y z qw qx qy qz of
every body, little-endian); ``hlvs/<match_id>/scene``: the replay header.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal

from contracts.codec import from_data, to_data

PREFIX = "hlvs"
Kind = Literal["state", "events", "poses", "scene"]
STATE: Kind = "state"
EVENTS: Kind = "events"
POSES: Kind = "poses"
SCENE: Kind = "scene"
KINDS: tuple[Kind, ...] = (STATE, EVENTS, POSES, SCENE)


def topic(match_id: str, kind: str) -> str:
    """The zenoh key of one telemetry stream (one of :data:`KINDS`) of a match."""
    return f"{PREFIX}/{match_id}/{kind}"


def match_topics(match_id: str) -> str:
    """The key expression of every telemetry stream of a match (for logs)."""
    return f"{PREFIX}/{match_id}/*"


@dataclass(frozen=True, slots=True, kw_only=True)
class StateMessage:
    """One ``hlvs/<match_id>/state`` message (JSON)."""

    sim_time_ms: int
    real_time_factor: float
    state: str | None  # GameController state name
    secondary_state: str | None
    half: int | None
    secs_remaining: float | None
    score: dict[str, int] | None  # {"red": goals, "blue": goals}
    connected: tuple[str, ...]  # robot keys connected to the robot API
    stepping: str
    robots: dict[str, Any] | None  # robot API traffic per robot key (simulator.traffic)

    def to_dict(self) -> dict[str, Any]:
        data: dict[str, Any] = to_data(self)
        return data

    @classmethod
    def from_dict(cls, data: Any, *, source: str) -> StateMessage:
        """Decode one message; :class:`~contracts.errors.ContractError` names the field."""
        return from_data(cls, data, source=source)


__all__ = [
    "EVENTS",
    "KINDS",
    "POSES",
    "PREFIX",
    "SCENE",
    "STATE",
    "Kind",
    "StateMessage",
    "match_topics",
    "topic",
]
