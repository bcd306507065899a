"""Penalty shoot-out: kicks alternate, each on the goal at x > 0, starting in SET.

Every kick: the kicking team plays "left" (its shoot-out poses are given for the goal at
x > 0), its kicker (first player without a red card) at its ``shootoutStartingPose``, the
defending goalkeeper at its ``goalKeeperStartingPose`` (mirrored), the others at their
half-time poses, the ball on the penalty mark. SET lasts 15 s (configurable), then the kicker
has 60 s. The kick ends with a goal (scored), the ball leaving the field, the ball stopping
after it moved, the kicker falling or the time running out (missed).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from contracts import Pose, RobotId, TeamColor
from referee.config import RefereeConfig
from referee.gamecontroller import GameController
from referee.rules.ball_out import in_goal, over_goal_line, over_touch_line
from referee.rules.base import ball_speed, distance2d
from referee.rules.end_of_game import ShootoutStatus, shootout_status
from referee.snapshot import PlaceBall, TeleportRobot, Vec3, WorldCommand, WorldSnapshot

STOPPED_M_S = 0.02
MOVED_M = 0.05


@dataclass(frozen=True, slots=True)
class KickOutcome:
    team: TeamColor
    kicker: RobotId
    scored: bool
    reason: str


def _teleport(robot: RobotId, pose: Pose) -> TeleportRobot:
    return TeleportRobot(robot=robot, pose=pose)


class Shootout:
    def __init__(self, *, config: RefereeConfig, first: TeamColor) -> None:
        self._config = config
        self.attacker = first
        self.kicker: RobotId | None = None
        self._ball_origin: Vec3 = (0.0, 0.0, 0.0)

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
        for player in attacking.players:
            robot = RobotId(self.attacker, player.number)
            if robot in red_carded:
                continue
            pose = player.shootout_pose if robot == self.kicker else player.half_time_pose
            commands.append(_teleport(robot, pose))
        for player in defending.players:
            robot = RobotId(self.attacker.opponent, player.number)
            if robot in red_carded:
                continue
            is_keeper = keeper_player is not None and player.number == keeper_player.number
            pose = player.goalkeeper_pose if is_keeper else player.half_time_pose
            commands.append(_teleport(robot, pose.mirrored()))
        self._ball_origin = (field.penalty_mark_x_m, 0.0, field.ball_radius_m)
        commands.append(PlaceBall(position=self._ball_origin))
        return commands

    def judge(self, snapshot: WorldSnapshot, time_left_s: float) -> KickOutcome | None:
        """While the kick runs (PLAYING)."""
        if self.kicker is None:
            return KickOutcome(self.attacker, RobotId(self.attacker, 0), False, "no kicker")
        field = self._config.field
        ball = snapshot.ball.position
        if in_goal(ball, field) and ball[0] > 0:
            return KickOutcome(self.attacker, self.kicker, True, "goal")
        if over_goal_line(ball, field) or over_touch_line(ball, field):
            return KickOutcome(self.attacker, self.kicker, False, "ball out")
        moved = distance2d(ball, self._ball_origin) >= MOVED_M
        if moved and ball_speed(snapshot) < STOPPED_M_S:
            return KickOutcome(self.attacker, self.kicker, False, "ball stopped")
        try:
            kicker = snapshot.robot(self.kicker)
        except KeyError:
            kicker = None
        if kicker is not None and kicker.fallen:
            return KickOutcome(self.attacker, self.kicker, False, "kicker fell")
        if time_left_s <= 0 or math.isnan(time_left_s):
            return KickOutcome(self.attacker, self.kicker, False, "time over")
        return None

    def record(self, gc: GameController, outcome: KickOutcome, *, seed: int) -> ShootoutStatus:
        """Count the kick on the GameController; is the shoot-out decided?"""
        gc.shootout_kick(outcome.team, outcome.scored)
        colors = (TeamColor.RED, TeamColor.BLUE)
        return shootout_status(
            taken={c: gc.teams[c].penalty_shots for c in colors},
            scored={c: bin(gc.teams[c].single_shots).count("1") for c in colors},
            seed=seed,
        )
