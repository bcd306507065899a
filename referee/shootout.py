"""Penalty shoot-out: kicks alternate, all on one goal, starting in SET.

As the league's referee plays it (hlvs_webots ``controllers/referee/referee.py``): the sides
change before every kick (``next_penalty_shootout`` 1627-1655, ``flip_sides`` 1490), so all
kicks are on the goal of the team that defends first, on its side when the shoot-out begins:
the ball on the penalty mark at x < 0 when the team on the left does not kick first, at x > 0
when it does (``set_penalty_positions`` 1574-1605, the ball's x at 1602). Every robot stands at
its team file's pose as written when its team plays on the left, mirrored when on the right
(``flip_pose`` 1480): the kicker (first player without a red card) at its
``shootoutStartingPose``, the defending goalkeeper at its ``goalKeeperStartingPose``, the
others at their half-time poses. SET lasts 15 s (configurable), then the kicker has 60 s.

Until the ball has moved 5 cm, in SET and PLAYING, the defending goalkeeper must stand on its
goal line or behind it, between the posts: off it for more than 1 s it is removed (INCAPABLE,
``check_penalty_goal_line`` 1657-1677, ``INVALID_GOALKEEPER_TIMEOUT`` in
``referee_config.yaml``). The kick ends with a goal (scored), the ball leaving the field, the
ball at rest in the goal area, the kicker fallen for longer than the fallen timeout or the
time running out (missed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from contracts import Pose, RobotId, TeamColor
from referee.config import RefereeConfig
from referee.gamecontroller import GameController
from referee.gamecontroller.states import Penalty
from referee.rules.ball_out import in_goal, over_goal_line, over_touch_line
from referee.rules.base import PenalizeRobot, ball_speed, distance2d
from referee.rules.end_of_game import ShootoutStatus, shootout_status
from referee.snapshot import PlaceBall, TeleportRobot, Vec3, WorldCommand, WorldSnapshot

STOPPED_M_S = 0.01  # STATIC_SPEED_EPS (hlvs_webots referee_config.yaml:36)
MOVED_M = 0.05
OFF_LINE_S = 1.0  # INVALID_GOALKEEPER_TIMEOUT (hlvs_webots referee_config.yaml:2)
# The league judges the goal line from the feet's contact points (a foot on the line counts):
# a goalkeeper's centre within half a foot's length and half the line's width of the line's
# centre stands on it (the league's own scenarios: 4.41 m on a 4.5 m half field is on the
# line, 4.27 m is off it).
ON_LINE_REACH_M = 0.125


@dataclass(frozen=True, slots=True)
class KickOutcome:
    team: TeamColor
    kicker: RobotId
    scored: bool
    reason: str


def _teleport(robot: RobotId, pose: Pose) -> TeleportRobot:
    return TeleportRobot(robot=robot, pose=pose)


class Shootout:
    def __init__(self, *, config: RefereeConfig, first: TeamColor, left: TeamColor) -> None:
        """``first`` kicks first; ``left`` plays on the left (x < 0) when the shoot-out begins."""
        self._config = config
        self.attacker = first
        self.kicker: RobotId | None = None
        self.keeper: RobotId | None = None
        self._ball_origin: Vec3 = (0.0, 0.0, 0.0)
        # every kick on the goal of the team that defends the first one (referee.py:1602)
        self.goal_sign = 1.0 if left is first else -1.0
        self._off_line_since_ms: int | None = None
        self._in_play = False  # the ball has moved 5 cm in this kick (the league's in_play)
        self._fallen_since_ms: int | None = None
        self._placed_ms = -1  # the world's time when this kick was set up

    @property
    def left_team(self) -> TeamColor:
        """The team on the left (x < 0) for the current kick."""
        return self.attacker if self.goal_sign > 0 else self.attacker.opponent

    def setup_kick(
        self, snapshot: WorldSnapshot, red_carded: set[RobotId], *, keeper: int | None = None
    ) -> list[WorldCommand]:
        """``keeper``: the defending goalkeeper's number (GameController flag)."""
        field = self._config.field
        commands: list[WorldCommand] = []
        attacking = self._config.team(self.attacker)
        defending = self._config.team(self.attacker.opponent)
        candidates = [
            p for p in attacking.players if RobotId(self.attacker, p.number) not in red_carded
        ]
        self.kicker = RobotId(self.attacker, candidates[0].number) if candidates else None
        keeper_player = next((p for p in defending.players if p.number == keeper), None)
        if keeper_player is None:
            keeper_player = next((p for p in defending.players if p.goalkeeper), None)
        if keeper_player is None and defending.players:
            keeper_player = defending.players[0]
        left = self.left_team
        for player in attacking.players:
            robot = RobotId(self.attacker, player.number)
            if robot in red_carded:
                continue
            pose = player.shootout_pose if robot == self.kicker else player.half_time_pose
            commands.append(_teleport(robot, pose.on_side(left=self.attacker is left)))
        self.keeper = None
        for player in defending.players:
            robot = RobotId(self.attacker.opponent, player.number)
            if robot in red_carded:
                continue
            is_keeper = keeper_player is not None and player.number == keeper_player.number
            if is_keeper:
                self.keeper = robot
            pose = player.goalkeeper_pose if is_keeper else player.half_time_pose
            commands.append(_teleport(robot, pose.on_side(left=self.attacker.opponent is left)))
        self._off_line_since_ms = None
        self._fallen_since_ms = None
        self._in_play = False
        self._placed_ms = snapshot.sim_time_ms
        self._ball_origin = (self.goal_sign * field.penalty_mark_x_m, 0.0, field.ball_radius_m)
        commands.append(PlaceBall(position=self._ball_origin))
        return commands

    def judge(self, snapshot: WorldSnapshot, time_left_s: float) -> KickOutcome | None:
        """While the kick runs (PLAYING), the league's ends of a trial (referee.py): a goal or
        the ball leaving the field (2234-2340), the ball at rest entirely inside the goal area
        (2178-2185, ``STATIC_SPEED_EPS``), the kicker fallen for longer than the fallen
        timeout (1122-1126), the time running out (2203-2208)."""
        if self.kicker is None:
            return KickOutcome(self.attacker, RobotId(self.attacker, 0), False, "no kicker")
        field = self._config.field
        ball = snapshot.ball.position
        if in_goal(ball, field) and ball[0] * self.goal_sign > 0:
            return KickOutcome(self.attacker, self.kicker, True, "goal")
        if over_goal_line(ball, field) or over_touch_line(ball, field):
            return KickOutcome(self.attacker, self.kicker, False, "ball out")
        if self._in_goal_area(ball) and ball_speed(snapshot) < STOPPED_M_S:
            return KickOutcome(self.attacker, self.kicker, False, "ball stopped in the goal area")
        try:
            kicker = snapshot.robot(self.kicker)
        except KeyError:
            kicker = None
        now = snapshot.sim_time_ms
        if kicker is not None and kicker.fallen:
            if self._fallen_since_ms is None:
                self._fallen_since_ms = now
            elif now - self._fallen_since_ms > self._config.timing.fallen_s * 1000.0:
                return KickOutcome(self.attacker, self.kicker, False, "kicker fell")
        else:
            self._fallen_since_ms = None
        if time_left_s <= 0 or math.isnan(time_left_s):
            return KickOutcome(self.attacker, self.kicker, False, "time over")
        return None

    def _in_goal_area(self, ball: Vec3) -> bool:
        """``circle_fully_inside_goal_area`` (hlvs_webots ``field.py:50-53``), on the goal
        kicked at."""
        field = self._config.field
        r = field.ball_radius_m
        x = ball[0] * self.goal_sign
        return (
            x - r > field.half_length_m - field.goal_area_length_m
            and x + r < field.half_length_m
            and abs(ball[1]) + r < field.goal_area_width_m / 2
        )

    def judge_goalkeeper(
        self, snapshot: WorldSnapshot, *, penalized: set[RobotId]
    ) -> list[PenalizeRobot]:
        """SET and PLAYING until the ball has moved 5 cm: the defending goalkeeper off its goal
        line (or in front of the goal's width) for more than 1 s is removed
        (``check_penalty_goal_line``, referee.py:1657-1677; the league's line is the whole
        goal width either side of the centre, ``abs(y) <= GOAL_WIDTH``, 1667)."""
        if snapshot.sim_time_ms <= self._placed_ms:
            return []  # the world before this kick's placement
        if self.ball_moved(snapshot):
            self._in_play = True
        if self.keeper is None or self.keeper in penalized or self._in_play:
            self._off_line_since_ms = None
            return []
        try:
            robot = snapshot.robot(self.keeper)
        except KeyError:
            self._off_line_since_ms = None
            return []
        field = self._config.field
        x, y = robot.position[0], robot.position[1]
        on_line_or_behind = (
            x * self.goal_sign >= field.half_length_m - ON_LINE_REACH_M
            and abs(y) <= field.goal_width_m
        )
        if on_line_or_behind:
            self._off_line_since_ms = None
            return []
        now = snapshot.sim_time_ms
        if self._off_line_since_ms is None:
            self._off_line_since_ms = now
            return []
        if now - self._off_line_since_ms <= OFF_LINE_S * 1000.0:
            return []
        self._off_line_since_ms = None
        return [
            PenalizeRobot(self.keeper, Penalty.PICKUP_OR_INCAPABLE, "not on the goal line")
        ]

    def ball_moved(self, snapshot: WorldSnapshot) -> bool:
        return distance2d(snapshot.ball.position, self._ball_origin) >= MOVED_M

    def record(self, gc: GameController, outcome: KickOutcome, *, seed: int) -> ShootoutStatus:
        """Count the kick on the GameController; is the shoot-out decided?"""
        gc.shootout_kick(outcome.team, outcome.scored)
        colors = (TeamColor.RED, TeamColor.BLUE)
        return shootout_status(
            taken={c: gc.teams[c].penalty_shots for c in colors},
            scored={c: bin(gc.teams[c].single_shots).count("1") for c in colors},
            seed=seed,
        )
