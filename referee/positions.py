"""Where the referee puts the robots and the ball before a period and for a kick-off.

Before each period (and before the shoot-out's first kick) every robot not sent off stands at
its team file's ``halfTimeStartingPose`` on its side, its limbs no longer limp, and the ball is
held off the field, as the league's referee holds it "in its hand" until SET
(hlvs_webots referee.py:1756-1768, ``move_ball_away`` called by ``kickoff``). When SET begins the
ball is put on the centre spot, wherever a robot pushed it in READY.
"""

from __future__ import annotations

import math
from dataclasses import replace

from contracts import RobotId, TeamColor
from referee.judgement import RefereeCore
from referee.snapshot import BallState, TeleportRobot, WorldCommand, WorldSnapshot

BALL_ON_SPOT_M = 0.01  # a ball farther from the centre spot at SET was moved in READY (logged)
# Where the ball is held before a kick-off, off the field, as the league's referee holds it
# "in its hand" (hlvs_webots referee.py:1756-1760, ``move_ball_away``)
BALL_AWAY_XY = (100.0, 100.0)


def starting_positions(ref: RefereeCore, sim_time_ms: int) -> list[WorldCommand]:
    """Every robot not sent off at its half-time starting pose (limp ones revived), the ball
    held away; logs each pose."""
    commands: list[WorldCommand] = []
    for color in (TeamColor.RED, TeamColor.BLUE):
        for player in ref.config.team(color).players:
            robot = RobotId(color, player.number)
            if robot in ref.book.red_carded:
                continue
            pose = player.half_time_pose.on_side(left=color is ref.left_team)
            ref.log.info(
                sim_time_ms,
                f"{robot} at halfTimeStartingPose ({pose.x_m:.2f}, {pose.y_m:.2f}, "
                f"{pose.yaw_rad:.2f}).",
            )
            commands.append(TeleportRobot(robot=robot, pose=pose))
            commands += ref.book.penalty_over(robot)
    ref.book.limp.clear()
    commands.append(ref.ball_away())
    return commands


def kick_off_ball(ref: RefereeCore, snapshot: WorldSnapshot) -> list[WorldCommand]:
    """SET begins: the ball is put on the centre spot, as the league's referee places it for
    the kick-off (or the dropped ball) when SET begins, wherever a robot pushed it in
    READY."""
    x, y = snapshot.ball.position[0], snapshot.ball.position[1]
    field = ref.field
    on_field = abs(x) <= field.turf_half_length_m and abs(y) <= field.turf_half_width_m
    if on_field and math.hypot(x, y) > BALL_ON_SPOT_M:
        ref.log.info(snapshot.sim_time_ms, f"Ball moved in READY to ({x:.2f}, {y:.2f}); "
                     "placed on the centre spot.")  # fmt: skip
    return [ref.ball_at(0.0, 0.0)]


def ball_held_placed(
    ref: RefereeCore, snapshot: WorldSnapshot
) -> tuple[list[WorldCommand], WorldSnapshot]:
    """A trainer puts the game into SET or PLAYING: a ball held off the field before a kick-off
    is put on the centre spot, as SET would have put it. Returns the commands and the snapshot
    as it will be (the ball on the spot, still)."""
    x, y = snapshot.ball.position[0], snapshot.ball.position[1]
    field = ref.field
    if abs(x) <= field.turf_half_length_m and abs(y) <= field.turf_half_width_m:
        return [], snapshot
    placed = ref.ball_at(0.0, 0.0)
    still = BallState(position=placed.position, velocity=(0.0, 0.0, 0.0))
    return [placed], replace(snapshot, ball=still)
