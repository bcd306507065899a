"""Telemetry keys (zenoh) the simulator publishes and the orchestrator and viewer subscribe to.

``hlvs/<match_id>/state``: JSON, about 5 Hz (sim_time_ms, real_time_factor, state,
secondary_state, half, secs_remaining, score, connected, stepping, robots);
``hlvs/<match_id>/events``: one JSON referee event per message;
``hlvs/<match_id>/poses``: about 10 Hz, binary (u32 sim_time_ms, then float32 x y z qw qx qy qz of
every body, little-endian); ``hlvs/<match_id>/scene``: the replay header.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, NotRequired, TypedDict

from contracts.codec import from_data, to_data
from contracts.jsontypes import JSONObject

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


class SetPlayRecord(TypedDict):
    team: str  # "red" | "blue"
    sub_phase: int


class PenaltyRecord(TypedDict):
    penalty: str  # GameController penalty name
    secs_till_unpenalised: int


class GameStateRecord(TypedDict, total=False):
    """The referee's game state as the telemetry carries it and the replay stores it per frame
    (empty before the referee's first step, so every key may be missing)."""

    state: str  # GameController state name
    secondary_state: str
    set_play: SetPlayRecord | None
    half: int
    phase: str
    secs_remaining: int
    kickoff: str  # "red" | "blue" | "dropped_ball"
    left_team: str
    score: dict[str, int]  # {"red": goals, "blue": goals}
    penalties: dict[str, PenaltyRecord]  # robot key ("red-1") -> its penalty
    waiting_for_wall_clock: bool


class EventRecord(TypedDict):
    """One referee event (``hlvs/<match_id>/events``, a replay frame's events)."""

    sim_time_ms: int
    type: str  # e.g. "goal", "ball_out", "penalty", "state", "dropped_ball", "card", "kickoff"
    team: str | None
    player: int | None
    reason: str
    placement: tuple[float, float, float] | list[float] | None
    details: dict[str, object]
    frame_ms: NotRequired[int]  # in a replay's event index: the frame it was recorded with


class RobotTraffic(TypedDict):
    """One robot's robot API traffic in a sample (totals since the start)."""

    connected: bool
    bytes_in: int
    bytes_out: int
    messages_in: int
    messages_out: int
    round_trip_ms: float | None  # mean round trip of this sample's replies; None without any


class TrafficSample(TypedDict):
    """One line of ``api_stats.jsonl`` (about once a wall-clock second)."""

    real_time_s: float
    sim_time_ms: int
    real_time_factor: float
    robots: dict[str, RobotTraffic]  # robot key ("red-1") -> its traffic


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
    robots: dict[str, RobotTraffic] | None  # robot API traffic per robot key

    def to_dict(self) -> JSONObject:
        data: JSONObject = to_data(self)
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
    "EventRecord",
    "GameStateRecord",
    "Kind",
    "PenaltyRecord",
    "RobotTraffic",
    "SetPlayRecord",
    "StateMessage",
    "TrafficSample",
    "match_topics",
    "topic",
]
