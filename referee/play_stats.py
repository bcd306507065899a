"""How much football was played: periods that reached PLAYING, kicks, shots, falls.

The referee feeds every snapshot to :class:`PlayTracker`; goals and own goals come from its goal
events. All of it is judged from ground truth (ball velocity, contacts, the simulator's fallen
flag), never from what the robots say.

- A **kick** is a touch of the ball by a robot after which, within ``KICK_WINDOW_MS``, the ball
  moves at least ``KICK_MIN_SPEED_M_S`` and ``KICK_MIN_GAIN_M_S`` faster than just before the
  touch (walking into the ball does not make it that fast). One kick per robot per
  ``KICK_WINDOW_MS``.
- A **shot** is a kick, made while the game runs, whose ball heads for the goal the kicker's team
  attacks: its straight path crosses that goal line between the posts, from no farther than half
  the field's length.
- A **fall** is a robot's fallen flag going from false to true (not while penalised or removed)
  after the robot stood for at least ``FALL_RECOVERED_MS``: the flag flickers while a robot
  struggles to get up, and that is still the same fall.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from contracts import PlayRecord, RobotId, TeamColor
from referee.gamecontroller import GameState, SecondaryState
from referee.rules.base import GameView
from referee.snapshot import RefereeEvent, WorldSnapshot

KICK_MIN_SPEED_M_S = 1.0
KICK_MIN_GAIN_M_S = 0.6
KICK_WINDOW_MS = 400
FALL_RECOVERED_MS = 1000
COLORS = (TeamColor.RED, TeamColor.BLUE)


def _per_team() -> dict[TeamColor, int]:
    return dict.fromkeys(COLORS, 0)


@dataclass(slots=True)
class _Touch:
    robot: RobotId
    time_ms: int
    speed_before_m_s: float


@dataclass(slots=True)
class PlayTracker:
    halves: set[int] = field(default_factory=set)
    playing_ms: int = 0
    kicks: dict[TeamColor, int] = field(default_factory=_per_team)
    shots: dict[TeamColor, int] = field(default_factory=_per_team)
    falls: dict[TeamColor, int] = field(default_factory=_per_team)
    _touches: dict[RobotId, _Touch] = field(default_factory=dict)
    _last_kick_ms: dict[RobotId, int] = field(default_factory=dict)
    _fallen: set[RobotId] = field(default_factory=set)
    _up_since_ms: dict[RobotId, int] = field(default_factory=dict)
    _last_ms: int | None = None
    _last_speed_m_s: float = 0.0

    def observe(self, snapshot: WorldSnapshot, view: GameView) -> None:
        now = snapshot.sim_time_ms
        dt_ms = 0 if self._last_ms is None else max(0, now - self._last_ms)
        self._last_ms = now
        playing = view.state is GameState.PLAYING
        if playing:
            self.playing_ms += dt_ms
            if view.phase is SecondaryState.NORMAL:
                self.halves.add(view.half)
        self._observe_falls(snapshot, view)
        ball = snapshot.ball
        speed = math.hypot(ball.velocity[0], ball.velocity[1])
        for robot in snapshot.robots:
            if robot.ball_contacts and robot.id not in self._touches:
                self._touches[robot.id] = _Touch(robot.id, now, self._last_speed_m_s)
        for robot_id, touch in list(self._touches.items()):
            if now - touch.time_ms > KICK_WINDOW_MS:
                del self._touches[robot_id]
                continue
            fast = speed >= KICK_MIN_SPEED_M_S
            if not fast or speed - touch.speed_before_m_s < KICK_MIN_GAIN_M_S:
                continue
            del self._touches[robot_id]
            last = self._last_kick_ms.get(robot_id)
            if not playing or (last is not None and now - last < KICK_WINDOW_MS):
                continue
            self._last_kick_ms[robot_id] = now
            self.kicks[robot_id.team] += 1
            if view.running and _towards_goal(snapshot, view, robot_id.team):
                self.shots[robot_id.team] += 1
        self._last_speed_m_s = speed

    def _observe_falls(self, snapshot: WorldSnapshot, view: GameView) -> None:
        now = snapshot.sim_time_ms
        for robot in snapshot.robots:
            down = robot.fallen and not robot.limp and not robot.removed
            if not down:
                if robot.id in self._fallen:
                    self._fallen.discard(robot.id)
                    self._up_since_ms[robot.id] = now
                continue
            if robot.id in self._fallen:
                continue
            self._fallen.add(robot.id)
            up_since = self._up_since_ms.get(robot.id)
            recovered = up_since is None or now - up_since >= FALL_RECOVERED_MS
            if recovered and robot.id not in view.penalised:
                self.falls[robot.id.team] += 1

    def stats(self, events: list[RefereeEvent]) -> PlayRecord:
        """What was counted, as the ``play`` record of the results (goals from ``events``)."""
        goals, own_goals = _per_team(), _per_team()
        for event in events:
            if event.type != "goal" or event.team is None:
                continue
            goals[event.team] += 1
            if event.details.get("own_goal"):
                own_goals[event.team.opponent] += 1
        return PlayRecord(
            halves_playing=tuple(sorted(self.halves)),
            both_halves_playing={1, 2} <= self.halves,
            playing_s=round(self.playing_ms / 1000.0, 3),
            kicks=_teams(self.kicks),
            shots=_teams(self.shots),
            goals=_teams(goals),
            own_goals=_teams(own_goals),
            falls=_teams(self.falls),
        )


def _teams(values: dict[TeamColor, int]) -> dict[str, int]:
    return {color.value: values[color] for color in COLORS}


def _towards_goal(snapshot: WorldSnapshot, view: GameView, team: TeamColor) -> bool:
    """The ball's straight path crosses the goal line ``team`` attacks between the posts."""
    geometry = view.field
    goal_x = -view.side_sign(team) * geometry.half_length_m  # the opponents' goal line
    (x, y, _), (vx, vy, _) = snapshot.ball.position, snapshot.ball.velocity
    if vx == 0.0 or (goal_x - x) / vx <= 0.0 or abs(goal_x - x) > geometry.half_length_m:
        return False
    y_at_line = y + vy * (goal_x - x) / vx
    return abs(y_at_line) < geometry.goal_width_m / 2.0


__all__ = ["PlayTracker"]
