"""The match spec: everything the simulator process needs, resolved, in one JSON file.

The orchestrator reads ``game.json`` and the team files (through its config layer), resolves every
default and random choice (sides and kick-off from the seed), and writes ``match_spec.json``; the
simulator process (``python -m simulator run --spec FILE``) reads only this file. Poses are given
as in HLVS team files: as if the team played on the left half (x < 0); the world mirrors them for
the team on the right.
"""

from __future__ import annotations

import json
from dataclasses import asdict, dataclass, field, fields, is_dataclass
from pathlib import Path
from typing import Any, Literal, TypeVar, get_args, get_origin, get_type_hints

from simulator.errors import SpecError

SPEC_VERSION = 1

GameType = Literal["NORMAL", "KNOCKOUT", "PENALTY"]
SteppingMode = Literal["async", "lockstep"]
Color = Literal["red", "blue"]


@dataclass(frozen=True, slots=True, kw_only=True)
class Pose:
    """A pose on the ground: torso x, y (z chosen by the world), heading."""

    x_m: float
    y_m: float
    yaw_rad: float


@dataclass(frozen=True, slots=True, kw_only=True)
class PlayerSpec:
    number: int  # 1..N
    model: str  # built-in robot model name, e.g. "kid-default"
    port: int  # robot API TCP port
    half_time_pose: Pose
    reentry_pose: Pose
    shootout_pose: Pose
    goalkeeper_pose: Pose
    goalkeeper: bool = False


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamSpec:
    color: Color
    team_id: int  # GameController team number
    name: str
    players: tuple[PlayerSpec, ...]
    hosts: tuple[str, ...]  # peer addresses allowed on this team's API ports (and mirror members)
    robot_addresses: tuple[str, ...] = ()  # where RGme is sent (UDP 3838); robot n at index n-1


@dataclass(frozen=True, slots=True, kw_only=True)
class TimingSpec:
    """Game timing. ``*_real_s`` are wall-clock waits; everything else is simulated time."""

    half_duration_s: float = 600.0
    overtime_half_duration_s: float = 300.0
    ready_duration_s: float = 45.0
    set_to_play_s: float = 5.0
    wait_before_first_ready_real_s: float = 120.0
    half_time_break_real_s: float = 15.0
    removal_penalty_s: float = 10.0
    end_of_game_real_s: float = 5.0
    max_duration_real_s: float | None = None  # stop the game after this wall time


@dataclass(frozen=True, slots=True, kw_only=True)
class NetworkSpec:
    api_bind_host: str = "0.0.0.0"
    gc_data_port: int = 3838
    gc_return_port: int = 3939
    mirror_port: int = 3737
    telemetry_listen: str | None = None  # zenoh endpoint, e.g. "tcp/172.30.0.2:7447"; None = off
    team_quota_mb_s: float = 350.0  # per real second per team, split evenly per robot
    rendering_quota_mb_s: float = 350.0  # per simulated second per team
    blocking_send: bool = False  # True restores the HLVS behaviour (a slow reader stalls the step)
    send_queue_messages: int = 64


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchSpec:
    match_id: str
    seed: int
    game_type: GameType
    field_class: Literal["kid", "adult"]
    side_left: Color  # team on x < 0 in the first half
    kickoff: Color  # team with the first kick-off
    red: TeamSpec
    blue: TeamSpec
    stepping: SteppingMode = "async"
    maximum_real_time_factor: float = 1.0  # <= 0: as fast as possible
    physics_dt_s: float = 0.002
    lockstep_deadline_ms: float = 50.0
    lockstep_time_bank_ms: float = 5000.0
    timing: TimingSpec = field(default_factory=TimingSpec)
    network: NetworkSpec = field(default_factory=NetworkSpec)
    record_video: str | None = None  # file name inside the output folder, e.g. "match.mp4"
    recorder_rate_hz: float = 25.0
    version: int = SPEC_VERSION

    def team(self, color: Color) -> TeamSpec:
        return self.red if color == "red" else self.blue

    def to_json(self) -> str:
        return json.dumps(asdict(self), indent=2, sort_keys=True)

    @classmethod
    def from_dict(cls, data: dict[str, Any], *, source: str = "<spec>") -> MatchSpec:
        return _build(cls, data, source=source, pointer="")

    @classmethod
    def load(cls, path: str | Path) -> MatchSpec:
        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8"))
        except (OSError, ValueError) as exc:
            raise SpecError(source=str(path), pointer="", reason=f"cannot read: {exc}") from exc
        if not isinstance(data, dict):
            raise SpecError(source=str(path), pointer="", reason="expected a JSON object")
        return cls.from_dict(data, source=str(path))


T = TypeVar("T")


def _build(cls: type[T], data: Any, *, source: str, pointer: str) -> T:
    if not isinstance(data, dict):
        raise SpecError(source=source, pointer=pointer, reason="expected an object")
    hints = get_type_hints(cls)
    names = {f.name for f in fields(cls)}  # type: ignore[arg-type]
    unknown = sorted(set(data) - names)
    if unknown:
        raise SpecError(source=source, pointer=f"{pointer}/{unknown[0]}", reason="unknown field")
    kwargs: dict[str, Any] = {}
    for name in names & set(data):
        kwargs[name] = _convert(hints[name], data[name], source=source, pointer=f"{pointer}/{name}")
    try:
        return cls(**kwargs)
    except TypeError as exc:
        raise SpecError(source=source, pointer=pointer, reason=str(exc)) from exc


def _convert(hint: Any, value: Any, *, source: str, pointer: str) -> Any:
    origin = get_origin(hint)
    args = get_args(hint)
    if is_dataclass(hint):
        return _build(hint, value, source=source, pointer=pointer)  # type: ignore[arg-type]
    if origin is tuple:
        if not isinstance(value, list | tuple):
            raise SpecError(source=source, pointer=pointer, reason="expected a list")
        item = args[0]
        return tuple(
            _convert(item, v, source=source, pointer=f"{pointer}/{i}") for i, v in enumerate(value)
        )
    if origin is Literal:
        if value not in args:
            raise SpecError(source=source, pointer=pointer, reason=f"expected one of {list(args)}")
        return value
    if args and type(None) in args:  # Optional
        if value is None:
            return None
        inner = [a for a in args if a is not type(None)][0]
        return _convert(inner, value, source=source, pointer=pointer)
    if hint is float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise SpecError(source=source, pointer=pointer, reason="expected a number")
        return float(value)
    if hint in (int, str, bool):
        if not isinstance(value, hint) or (hint is int and isinstance(value, bool)):
            raise SpecError(source=source, pointer=pointer, reason=f"expected {hint.__name__}")
        return value
    return value
