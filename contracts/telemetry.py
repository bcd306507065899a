"""Telemetry keys (zenoh) the simulator publishes and the orchestrator and viewer subscribe to.

``hlvs/<match_id>/state``: JSON, about 5 Hz (sim_time_ms, real_time_factor, state,
secondary_state, half, secs_remaining, score, connected, stepping, robots);
``hlvs/<match_id>/events``: one JSON referee event per message;
``hlvs/<match_id>/poses``: about 10 Hz, binary (u32 sim_time_ms, then float32 x y z qw qx qy qz of
every body, little-endian); ``hlvs/<match_id>/scene``: the replay header.
"""

from __future__ import annotations

from typing import Literal

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


__all__ = ["EVENTS", "KINDS", "POSES", "PREFIX", "SCENE", "STATE", "Kind", "match_topics", "topic"]
