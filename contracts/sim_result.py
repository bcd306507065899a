"""``sim_result.json``: what the simulator reports when its process ends.

Written by the simulator (``simulator.runtime``) and by the orchestrator's fake runtime in unit
tests, read by the orchestrator's runner and results; all three use this one type.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import ClassVar, Literal, TypedDict

from contracts.codec import Versioned
from contracts.jsontypes import JSONObject

Winner = Literal["red", "blue", "draw"]


class RobotApiStats(TypedDict):
    """One robot's robot API statistics over the whole match (all its connections)."""

    connects: list[float]  # unix s
    disconnects: list[float]
    disconnect_reasons: list[str]
    refused_connections: int
    messages_in: int
    bytes_in: int
    messages_out: int
    bytes_out: int
    dropped_out: int
    dropped_in: dict[str, int]  # requests dropped undecoded, by reason ("size")
    dropped_in_bytes: int
    quota_errors: int
    bad_frames: int
    decode_errors: int
    missed_deadlines: int
    slow_periods: int
    warnings_sent: int
    round_trip_ms: dict[str, float | None]  # p50, p90, p99, max (None without replies)
    round_trip_samples: int
    # the client's round trip seen from the server: its request's first byte received to the
    # next measurement's last byte written; p50, p90, p99, max (None without replies)
    reply_ms: dict[str, float | None]
    reply_samples: int


# the simulator's camera render processes at most (one per CPU it may use, on the CPU renderer);
# the orchestrator gives an async match's simulator up to this many spare CPUs for them
MAX_RENDER_PROCESSES = 4


class CameraRecord(TypedDict, total=False):
    """What the simulator rendered for the robots' cameras, and with which OpenGL (empty from a
    simulator that did not report it)."""

    frames: int
    render_s: float
    render_processes: int  # 0: one render thread in the simulator process; <= MAX_RENDER_PROCESSES
    gl_backend: str
    gl_renderer: str  # llvmpipe: the CPU
    gl_error: str  # no offscreen OpenGL: camera requests failed
COLORS = ("red", "blue")


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayRecord:
    """How much football the referee saw (``play`` of ``sim_result.json`` and ``results.json``).

    ``halves_playing``: halves of regular time that reached PLAYING; ``playing_s``: simulated
    seconds in PLAYING; kicks, shots (kicks heading between the posts of the goal attacked),
    goals (own goals included), own goals (scored by the team's own players) and falls are
    counted per team colour.
    """

    halves_playing: tuple[int, ...]
    both_halves_playing: bool
    playing_s: float
    kicks: dict[str, int]
    shots: dict[str, int]
    goals: dict[str, int]
    own_goals: dict[str, int]
    falls: dict[str, int]

    def __post_init__(self) -> None:
        for name in ("kicks", "shots", "goals", "own_goals", "falls"):
            counts = getattr(self, name)
            if set(counts) != set(COLORS) or any(n < 0 for n in counts.values()):
                raise ValueError(f"{name}: expected counts >= 0 for red and blue, got {counts}")
        if self.both_halves_playing != ({1, 2} <= set(self.halves_playing)):
            raise ValueError("both_halves_playing disagrees with halves_playing")


@dataclass(frozen=True, slots=True, kw_only=True)
class SpoofingAttempt:
    """One kind of attempt: ``count`` messages on ``channel`` from ``sender`` claiming
    ``claimed`` (``None`` when it claimed no robot of this match)."""

    channel: str  # "gamecontroller" | "mirror" | "api"
    sender: str  # source IP address
    sender_robot: str | None  # the robot at that address ("red-1"), None if none
    claimed: str | None  # the robot the message claimed to be ("blue-2")
    message: str  # what it asked for (RGrt message name, "team message", "connect")
    count: int = 1

    def to_json(self) -> dict[str, object]:
        return {
            "channel": self.channel,
            "sender": self.sender,
            "sender_robot": self.sender_robot,
            "claimed": self.claimed,
            "message": self.message,
            "count": self.count,
        }

    def describe(self) -> str:
        who = f"{self.sender} ({self.sender_robot})" if self.sender_robot else self.sender
        claimed = self.claimed or "no robot of this match"
        return (f"spoofing on {self.channel}: {self.message} from {who} claiming to be "
                f"{claimed} ignored")


@dataclass(frozen=True, slots=True, kw_only=True)
class SpoofingRecord:
    """Messages robots sent as another robot (``spoofing`` of ``sim_result.json`` and
    ``results.json``): ``total`` messages, ``attempts`` grouped by kind (the first ones)."""

    total: int
    attempts: tuple[SpoofingAttempt, ...] = ()

    def per_sender(self) -> dict[str, int]:
        """Messages each robot (``red-1``) sent as another robot."""
        counts: dict[str, int] = {}
        for attempt in self.attempts:
            sender = str(attempt.sender_robot)
            counts[sender] = counts.get(sender, 0) + attempt.count
        return counts


@dataclass(frozen=True, slots=True, kw_only=True)
class SimResult(Versioned):
    VERSION: ClassVar[int] = 1
    KIND: ClassVar[str] = "simulator result"

    match_id: str
    seed: int
    state: str  # GameController state at the end: FINISHED when the game was played out
    score: dict[str, int]  # {"red": goals, "blue": goals}
    winner: Winner | None  # None while the game is not over
    events_summary: dict[str, int] = field(default_factory=dict)  # referee event type -> count
    stop_reason: str = "finished"  # finished | SIGTERM | SIGINT | time_limit | internal_error ...
    error: str = ""  # what went wrong when the process failed
    stepping: str = "async"
    sim_time_ms: int = 0
    real_time_s: float = 0.0
    held_real_s: float = 0.0  # wall time the world was held (waiting for robots)
    real_time_factor: float = 0.0
    robots: dict[str, RobotApiStats] = field(default_factory=dict)  # robot key -> its API use
    cameras: CameraRecord = field(default_factory=lambda: CameraRecord())
    started_unix_s: float = 0.0
    versions: dict[str, str] = field(default_factory=dict)  # distribution -> version
    spoofing: SpoofingRecord | None = None
    shootout: dict[str, dict[str, int]] | None = None  # color -> kicks, scored
    coin_toss: bool | None = None  # decided by a coin toss after the shoot-out
    play: PlayRecord | None = None  # None from a simulator that did not count play
    version: int = VERSION

    def to_dict(self) -> JSONObject:
        data = Versioned.to_dict(self)
        for optional in ("shootout", "coin_toss"):  # only written when there was a shoot-out
            if data[optional] is None:
                del data[optional]
        return data

    @property
    def finished(self) -> bool:
        return self.state == "FINISHED"


__all__ = [
    "MAX_RENDER_PROCESSES",
    "CameraRecord",
    "PlayRecord",
    "RobotApiStats",
    "SimResult",
    "SpoofingAttempt",
    "SpoofingRecord",
    "Winner",
]
