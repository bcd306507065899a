"""The league's referee test scenarios (``test_scenario.json`` of hlvs_webots) as data.

A scenario is a JSON list of steps; each step has a ``timing`` and optional ``tests`` and
``actions`` (``controllers/test_supervisor/rc_testing.py`` of hlvs_webots builds them:
``Event.buildFromDictionary`` 601-614, ``TimeSpecification.buildFromDictionary`` 218-233,
``Test.buildFromDictionary`` 357-379, ``Action.buildFromDictionary`` 491-503)::

    [{"description": "...",
      "timing": {"time": 5.0, "clock_type": "Simulated", "state": "READY", "state_count": 1},
      "tests": [{"name": "...", "target": "RED_PLAYER_1", "penalty": 0, "critical": true}],
      "actions": [{"target": "BALL", "position": [1, 3, 0.08], "force": [0, 5, 0]}]}]

``time`` is a number (a point: the step runs once, at the first basic step after it) or
``[start, end]`` (an interval: every basic step in ``(start, end]``), in seconds since the
``state_count``-th time the game reached ``state`` (or ``secondary_state`` in ``phase``), or
since the start when neither is named. The league's runner reads only the keys listed here and
ignores any other; so does this loader, and it lists the ignored keys of each test so a reader
sees what a test does not check. What the runner cannot read at all (not JSON, a step without
``timing``, a malformed time, an unknown state, a target it cannot resolve) is a
:class:`~referee.errors.ScenarioError` naming the file and the JSON pointer.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from contracts import RobotId, TeamColor
from referee.errors import ScenarioError

# rc_testing.py:22-24
VALID_STATES = ("INITIAL", "READY", "SET", "PLAYING", "FINISHED")
VALID_SECONDARY_STATES = (
    "NORMAL", "PENALTYSHOOT", "OVERTIME", "TIMEOUT", "DIRECT_FREEKICK", "INDIRECT_FREEKICK",
    "PENALTYKICK", "CORNERKICK", "GOALKICK", "THROWIN", "DROPBALL", "UNKNOWN",
)  # fmt: skip
POSITION_TOLERANCE_M = 0.03  # rc_testing.py:19 POS_ABS_TOL
Clock = Literal["Simulated", "System"]
TEST_KEYS = (
    "name", "target", "position", "rotation", "state", "secondary_state", "secondary_team_id",
    "secondary_phase", "penalty", "warnings", "yellow_cards", "red_cards", "score",
    "kick_off_team", "critical", "abs_tol",
)  # fmt: skip
ACTION_KEYS = ("target", "position", "orientation", "force", "velocity")
STEP_KEYS = ("timing", "tests", "actions")
_TARGET_NEEDED = ("position", "penalty", "warnings", "yellow_cards", "red_cards", "score")


@dataclass(frozen=True, slots=True)
class LeagueTarget:
    """``BALL``, ``RED`` / ``BLUE`` (a team) or ``RED_PLAYER_3`` (a robot)."""

    name: str
    team: TeamColor | None = None
    number: int | None = None

    @property
    def is_ball(self) -> bool:
        return self.name == "BALL"

    @property
    def robot(self) -> RobotId | None:
        if self.team is None or self.number is None:
            return None
        return RobotId(self.team, self.number)


@dataclass(frozen=True, slots=True)
class LeagueTiming:
    start_s: float  # a point's time, or an interval's start
    end_s: float | None  # None: a point
    clock: Clock
    state: str | None
    state_count: int
    secondary_state: str | None
    phase: int | None

    def describe(self) -> str:
        start, end = self.start_s, self.end_s
        when = f"{start:g} s" if end is None else f"({start:g}, {end:g}] s"
        if self.state is not None:
            since = f"{self.state}#{self.state_count}"
        elif self.secondary_state is not None:
            since = f"{self.secondary_state} phase {self.phase}#{self.state_count}"
        else:
            since = "start"
        return f"{when} after {since} ({self.clock})"


@dataclass(frozen=True, slots=True)
class LeagueTest:
    pointer: str
    name: str
    target: LeagueTarget | None
    critical: bool
    checks: dict[str, Any]  # the league's test keys that check something, with their values
    abs_tol: float
    ignored: tuple[str, ...]  # keys the league's runner does not read


@dataclass(frozen=True, slots=True)
class LeagueAction:
    pointer: str
    target: LeagueTarget
    position: tuple[float, float, float] | None
    orientation: tuple[float, float, float, float] | None
    force: tuple[float, float, float] | None
    velocity: tuple[float, ...] | None  # 6 values (3 given: the angular ones are zero)


@dataclass(frozen=True, slots=True)
class LeagueStep:
    index: int
    pointer: str
    description: str
    timing: LeagueTiming
    tests: tuple[LeagueTest, ...]
    actions: tuple[LeagueAction, ...]


@dataclass(frozen=True, slots=True)
class LeagueScenario:
    path: Path
    steps: tuple[LeagueStep, ...]

    @property
    def test_count(self) -> int:
        return sum(len(s.tests) for s in self.steps)


class _Reader:
    def __init__(self, path: Path) -> None:
        self.where = str(path)

    def fail(self, pointer: str, reason: str) -> ScenarioError:
        return ScenarioError(path=self.where, pointer=pointer, reason=reason)

    def mapping(self, value: object, pointer: str) -> dict[str, Any]:
        if not isinstance(value, dict):
            raise self.fail(pointer, f"expected an object, got {_kind(value)}")
        return value

    def number(self, value: object, pointer: str) -> float:
        if isinstance(value, bool) or not isinstance(value, int | float):
            raise self.fail(pointer, f"expected a number, got {value!r}")
        if not math.isfinite(value):
            raise self.fail(pointer, f"expected a finite number, got {value!r}")
        return float(value)

    def integer(self, value: object, pointer: str, *, minimum: int = 0) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < minimum:
            raise self.fail(pointer, f"expected an integer >= {minimum}, got {value!r}")
        return value

    def vector(self, value: object, pointer: str, sizes: tuple[int, ...]) -> tuple[float, ...]:
        if not isinstance(value, list) or len(value) not in sizes:
            wanted = " or ".join(str(n) for n in sizes)
            raise self.fail(pointer, f"expected a list of {wanted} numbers, got {value!r}")
        return tuple(self.number(v, f"{pointer}/{i}") for i, v in enumerate(value))

    def choice(self, value: object, pointer: str, choices: tuple[str, ...]) -> str:
        if value not in choices:
            raise self.fail(pointer, f"expected one of {', '.join(choices)}, got {value!r}")
        return str(value)

    def target(self, value: object, pointer: str) -> LeagueTarget:
        """rc_testing.py:385-395 (a team or one of its players) and ``getFromDef`` (a robot's
        or the ball's DEF name in the league's world)."""
        if value == "BALL":
            return LeagueTarget("BALL")
        if isinstance(value, str):
            parts = value.split("_")
            color = {"RED": TeamColor.RED, "BLUE": TeamColor.BLUE}.get(parts[0])
            if color is not None and len(parts) == 1:
                return LeagueTarget(value, color)
            player = len(parts) == 3 and parts[1] == "PLAYER" and parts[2].isdigit()
            if color is not None and player:
                number = int(parts[2])
                if number >= 1:
                    return LeagueTarget(value, color, number)
        raise self.fail(
            pointer, f"expected BALL, RED, BLUE or RED_PLAYER_<n> / BLUE_PLAYER_<n>, got {value!r}"
        )


def _kind(value: object) -> str:
    if isinstance(value, dict):
        return "an object"
    if isinstance(value, list):
        return "a list"
    return repr(value)


def _timing(r: _Reader, raw: object, pointer: str) -> LeagueTiming:
    data = r.mapping(raw, pointer)
    if "time" not in data:
        raise r.fail(pointer, "missing 'time' (a number, or [start, end])")
    t = data["time"]
    if isinstance(t, list):
        if len(t) != 2:
            raise r.fail(f"{pointer}/time", f"an interval is [start, end], got {len(t)} values")
        start = r.number(t[0], f"{pointer}/time/0")
        end: float | None = r.number(t[1], f"{pointer}/time/1")
    else:
        start, end = r.number(t, f"{pointer}/time"), None
    clock = r.choice(data.get("clock_type", "Simulated"), f"{pointer}/clock_type",
                     ("Simulated", "System"))  # fmt: skip
    state = data.get("state")
    if state is not None:
        state = r.choice(state, f"{pointer}/state", VALID_STATES)
    secondary = data.get("secondary_state")
    phase = data.get("phase")
    if secondary is not None:
        secondary = r.choice(secondary, f"{pointer}/secondary_state", VALID_SECONDARY_STATES)
        if phase is None:  # rc_testing.py:160 compares the phase: the league's runner stops
            raise r.fail(f"{pointer}/phase", "a secondary_state timing needs its phase (0, 1 or 2)")
        phase = r.integer(phase, f"{pointer}/phase")
        if phase > 2:
            raise r.fail(f"{pointer}/phase", f"expected 0, 1 or 2, got {phase}")
    elif phase is not None:
        phase = r.integer(phase, f"{pointer}/phase")  # read, unused without secondary_state
    count = r.integer(data.get("state_count", 1), f"{pointer}/state_count", minimum=1)
    return LeagueTiming(
        start_s=start,
        end_s=end,
        clock="System" if clock == "System" else "Simulated",
        state=state,
        state_count=count,
        secondary_state=secondary,
        phase=phase,
    )


def _test(r: _Reader, raw: object, pointer: str) -> LeagueTest:
    data = r.mapping(raw, pointer)
    if "name" not in data:
        raise r.fail(pointer, "a test needs a 'name'")
    target = None
    if data.get("target") is not None:
        target = r.target(data["target"], f"{pointer}/target")
    checks: dict[str, Any] = {}
    for key in ("state",):
        if data.get(key) is not None:
            checks[key] = r.choice(data[key], f"{pointer}/{key}", VALID_STATES)
    if data.get("secondary_state") is not None:
        checks["secondary_state"] = r.choice(
            data["secondary_state"], f"{pointer}/secondary_state", VALID_SECONDARY_STATES
        )
    for key in ("secondary_team_id", "secondary_phase", "penalty", "warnings", "yellow_cards",
                "red_cards", "score", "kick_off_team"):  # fmt: skip
        if data.get(key) is not None:
            checks[key] = r.integer(data[key], f"{pointer}/{key}")
    if data.get("position") is not None:
        checks["position"] = r.vector(data["position"], f"{pointer}/position", (3,))
    for key in _TARGET_NEEDED:
        if key in checks and target is None:
            raise r.fail(pointer, f"a test of '{key}' needs a 'target'")
    if target is not None:
        if "position" in checks and target.robot is None and not target.is_ball:
            raise r.fail(f"{pointer}/target", "a position is tested on BALL or a robot")
        team_data = [k for k in ("penalty", "warnings", "yellow_cards", "red_cards") if k in checks]
        if team_data and target.robot is None:
            raise r.fail(f"{pointer}/target", f"'{team_data[0]}' is tested on a robot")
        if "score" in checks and target.team is None:
            raise r.fail(f"{pointer}/target", "a score is tested on RED, BLUE or one of theirs")
    tol = r.number(data.get("abs_tol", POSITION_TOLERANCE_M), f"{pointer}/abs_tol")
    critical = data.get("critical", False)
    if not isinstance(critical, bool):
        raise r.fail(f"{pointer}/critical", f"expected true or false, got {critical!r}")
    return LeagueTest(
        pointer=pointer,
        name=str(data["name"]),
        target=target,
        critical=critical,
        checks=checks,
        abs_tol=tol,
        # rotation: read and never checked by the league's runner (rc_testing.py:413-419)
        ignored=tuple(k for k in data if k not in TEST_KEYS or k == "rotation"),
    )


def _action(r: _Reader, raw: object, pointer: str) -> LeagueAction:
    data = r.mapping(raw, pointer)
    if "target" not in data:
        raise r.fail(pointer, "an action needs a 'target'")
    target = r.target(data["target"], f"{pointer}/target")
    if target.robot is None and not target.is_ball:
        raise r.fail(f"{pointer}/target", "an action moves BALL or a robot, not a team")

    def vec(key: str, sizes: tuple[int, ...]) -> tuple[float, ...] | None:
        return None if data.get(key) is None else r.vector(data[key], f"{pointer}/{key}", sizes)

    position, orientation = vec("position", (3,)), vec("orientation", (4,))
    force = vec("force", (3,))
    velocity = vec("velocity", (3, 6))
    if velocity is not None and len(velocity) == 3:
        velocity = (*velocity, 0.0, 0.0, 0.0)  # rc_testing.py:500-501
    if orientation is not None and not any(orientation[:3]):
        raise r.fail(f"{pointer}/orientation", "the rotation axis is zero")
    unknown = [k for k in data if k not in ACTION_KEYS]
    if unknown:
        known = ", ".join(ACTION_KEYS)
        raise r.fail(f"{pointer}/{unknown[0]}", f"unknown action key; known: {known}")
    return LeagueAction(
        pointer=pointer,
        target=target,
        position=None if position is None else (position[0], position[1], position[2]),
        orientation=None if orientation is None else (
            orientation[0], orientation[1], orientation[2], orientation[3]),
        force=None if force is None else (force[0], force[1], force[2]),
        velocity=velocity,
    )  # fmt: skip


def parse_league_scenario(document: object, *, path: Path) -> LeagueScenario:
    """The scenario of ``document`` (a parsed ``test_scenario.json``) read from ``path``."""
    r = _Reader(path)
    if not isinstance(document, list):
        raise r.fail("", f"expected a list of steps, got {_kind(document)}")
    steps = []
    for i, raw in enumerate(document):
        pointer = f"/{i}"
        data = r.mapping(raw, pointer)
        if "timing" not in data:
            raise r.fail(pointer, "a step needs a 'timing'")
        tests = data.get("tests") or []
        actions = data.get("actions") or []
        if not isinstance(tests, list):
            raise r.fail(f"{pointer}/tests", "expected a list of tests")
        if not isinstance(actions, list):
            raise r.fail(f"{pointer}/actions", "expected a list of actions")
        steps.append(
            LeagueStep(
                index=i,
                pointer=pointer,
                description=str(data.get("description", "")),
                timing=_timing(r, data["timing"], f"{pointer}/timing"),
                tests=tuple(_test(r, t, f"{pointer}/tests/{j}") for j, t in enumerate(tests)),
                actions=tuple(
                    _action(r, a, f"{pointer}/actions/{j}") for j, a in enumerate(actions)
                ),
            )
        )
    return LeagueScenario(path=path, steps=tuple(steps))


def load_league_scenario(path: Path) -> LeagueScenario:
    """Read and parse ``path``; a file that cannot be read or parsed raises ScenarioError."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ScenarioError(path=str(path), pointer="", reason=f"cannot read: {exc}") from exc
    try:
        document = json.loads(text)
    except json.JSONDecodeError as exc:
        raise ScenarioError(
            path=str(path), pointer="",
            reason=f"not JSON: {exc.msg} at line {exc.lineno} column {exc.colno}",
        ) from exc
    return parse_league_scenario(document, path=path)


__all__ = [
    "LeagueAction",
    "LeagueScenario",
    "LeagueStep",
    "LeagueTarget",
    "LeagueTest",
    "LeagueTiming",
    "load_league_scenario",
    "parse_league_scenario",
]
