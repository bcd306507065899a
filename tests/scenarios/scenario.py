"""Referee scenarios as data: loading and validating ``tests/scenarios/<rule>/<case>.yaml``.

A scenario file::

    description: what the case shows
    game: {type: NORMAL, side_left: red, kickoff: red, half: 1}   # all optional
    timing: {fallen_s: 3}                                       # TimingConfig overrides
    robots:                                                     # world poses in the start half
      - {id: red-1, x: -1.0, y: 0.5, yaw: 0.0, goalkeeper: false}
    duration_s: 12
    actions:                                                    # at simulated times
      - {at_s: 4.0, place_ball: {x: 1.0, y: 2.9, vx: 0.0, vy: 1.0}}
      - {at_s: 4.0, teleport: {robot: red-1, x: 0.5, y: 0.0, yaw: 0.0}}
      - {at_s: 4.0, until_s: 5.0, push: {robot: red-1, vx: 0.5, vy: 0.0}}   # root velocity
      - {at_s: 4.0, fall: {robot: blue-2}}                                   # lay it down
    expect:
      - {at_s: 6.0, state: PLAYING, secondary_state: THROW_IN, set_play_team: blue}
      - {at_s: 6.0, penalised: [red-1], score: {red: 0, blue: 0}}
      - {event: {type: throw_in, team: blue, within_s: [4, 6]}}
      - {no_event: {type: goal}}

Times are simulated seconds from the start of the match. ``game.half: 2`` starts the scenario in
the second half: the runner makes the first half last ``first_half_s`` (default 2 s) and the
robot poses are the ones for the second half.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

from contracts.ids import RobotId, TeamColor
from referee.errors import ScenarioError

STATE_KEYS = {
    "state",
    "secondary_state",
    "half",
    "score",
    "kickoff",
    "set_play_team",
    "sub_phase",
    "left_team",
    "penalised",
    "not_penalised",
    "limp",
    "not_limp",
    "finished",
    "winner",
    "waiting",
    "ball_near",
    "robot_near",
    "cards",
    "removed",
    "phase",
    "secs_remaining",
}
ACTIONS = {"place_ball", "teleport", "push", "fall", "kick", "card"}


@dataclass(frozen=True, slots=True)
class RobotStart:
    id: RobotId
    x: float
    y: float
    yaw: float
    goalkeeper: bool


@dataclass(frozen=True, slots=True)
class Action:
    at_s: float
    until_s: float | None
    kind: str
    args: dict[str, Any]


@dataclass(frozen=True, slots=True)
class Expectation:
    pointer: str
    at_s: float | None
    checks: dict[str, Any]  # STATE_KEYS at at_s, or {"event": ...} / {"no_event": ...}


@dataclass(frozen=True, slots=True)
class Scenario:
    path: Path
    name: str
    description: str
    game: dict[str, Any]
    timing: dict[str, float]
    robots: tuple[RobotStart, ...]
    ball: tuple[float, float]
    duration_s: float
    actions: tuple[Action, ...]
    expectations: tuple[Expectation, ...]


def parse_robot_id(text: object, *, path: str, pointer: str) -> RobotId:
    if not isinstance(text, str) or "-" not in text:
        raise ScenarioError(
            path=path, pointer=pointer, reason=f"expected 'red-N' or 'blue-N', got {text!r}"
        )
    team, _, number = text.partition("-")
    try:
        return RobotId(TeamColor(team), int(number))
    except ValueError as exc:
        raise ScenarioError(path=path, pointer=pointer, reason=f"bad robot id {text!r}") from exc


def _number(
    data: dict[str, Any], key: str, *, path: str, pointer: str, default: float | None = None
) -> float:
    value = data.get(key, default)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ScenarioError(path=path, pointer=f"{pointer}/{key}", reason="expected a number")
    return float(value)


def _mapping(value: object, *, path: str, pointer: str) -> dict[str, Any]:
    if not isinstance(value, dict):
        raise ScenarioError(path=path, pointer=pointer, reason="expected a mapping")
    return value


def load(path: Path) -> Scenario:
    where = str(path)
    try:
        raw = yaml.safe_load(path.read_text(encoding="utf-8"))
    except (OSError, yaml.YAMLError) as exc:
        raise ScenarioError(path=where, pointer="", reason=f"cannot read: {exc}") from exc
    data = _mapping(raw, path=where, pointer="")
    unknown = set(data) - {
        "description",
        "game",
        "timing",
        "robots",
        "ball",
        "duration_s",
        "actions",
        "expect",
    }
    if unknown:
        raise ScenarioError(path=where, pointer=f"/{sorted(unknown)[0]}", reason="unknown key")
    robots = []
    for i, item in enumerate(data.get("robots", [])):
        pointer = f"/robots/{i}"
        item = _mapping(item, path=where, pointer=pointer)
        robots.append(
            RobotStart(
                id=parse_robot_id(item.get("id"), path=where, pointer=f"{pointer}/id"),
                x=_number(item, "x", path=where, pointer=pointer),
                y=_number(item, "y", path=where, pointer=pointer),
                yaw=_number(item, "yaw", path=where, pointer=pointer, default=0.0),
                goalkeeper=bool(item.get("goalkeeper", False)),
            )
        )
    ball = _mapping(data.get("ball", {}), path=where, pointer="/ball")
    actions = []
    for i, item in enumerate(data.get("actions", [])):
        pointer = f"/actions/{i}"
        item = _mapping(item, path=where, pointer=pointer)
        kinds = [k for k in item if k in ACTIONS]
        if len(kinds) != 1:
            raise ScenarioError(
                path=where, pointer=pointer, reason=f"expected exactly one of {sorted(ACTIONS)}"
            )
        until = item.get("until_s")
        actions.append(
            Action(
                at_s=_number(item, "at_s", path=where, pointer=pointer),
                until_s=None if until is None else float(until),
                kind=kinds[0],
                args=_mapping(item[kinds[0]], path=where, pointer=f"{pointer}/{kinds[0]}"),
            )
        )
    expectations = []
    for i, item in enumerate(data.get("expect", [])):
        pointer = f"/expect/{i}"
        item = _mapping(item, path=where, pointer=pointer)
        checks = {k: v for k, v in item.items() if k != "at_s"}
        bad = set(checks) - STATE_KEYS - {"event", "no_event"}
        if bad:
            raise ScenarioError(
                path=where,
                pointer=f"{pointer}/{sorted(bad)[0]}",
                reason=f"unknown check; known: {sorted(STATE_KEYS)}",
            )
        state_checks = set(checks) & STATE_KEYS
        if state_checks and "at_s" not in item:
            raise ScenarioError(path=where, pointer=pointer, reason="state checks need at_s")
        at = item.get("at_s")
        expectations.append(Expectation(pointer, None if at is None else float(at), checks))
    if not expectations:
        raise ScenarioError(
            path=where, pointer="/expect", reason="a scenario must expect something"
        )
    return Scenario(
        path=path,
        name=f"{path.parent.name}/{path.stem}",
        description=str(data.get("description", "")),
        game=_mapping(data.get("game", {}), path=where, pointer="/game"),
        timing={
            k: float(v)
            for k, v in _mapping(data.get("timing", {}), path=where, pointer="/timing").items()
        },
        robots=tuple(robots),
        ball=(float(ball.get("x", 0.0)), float(ball.get("y", 0.0))),
        duration_s=_number(data, "duration_s", path=where, pointer=""),
        actions=tuple(actions),
        expectations=tuple(expectations),
    )


def discover(root: Path) -> list[Path]:
    return sorted(root.glob("*/*.yaml"))
