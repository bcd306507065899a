"""Removal of a penalised robot and its re-entry.

A removed robot is placed at its re-entry pose: x on the penalty-mark line of its own half, y at
the touch line on the side opposite to the ball (the y of its ``reentryStartingPose``, sign
chosen away from the ball), shifted along the line by the penalty offset when another robot
stands there. It is taken out of its team's control (``SetLimp``: the world holds it in its
standing pose, as a referee carries a removed robot, so it neither folds up nor counts a fall)
until the GameController's penalty time is over, then its team's commands apply again and it
walks back in by itself. A red card removes the robot
from the world.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

from contracts import FieldGeometry, Pose, RobotId
from referee.snapshot import (
    RemoveRobot,
    SetLimp,
    TeleportRobot,
    Vec2,
    WorldCommand,
    WorldSnapshot,
)


def reentry_pose(
    *,
    template: Pose,
    side_sign: float,
    ball_y_m: float,
    occupied: Sequence[Vec2],
    field: FieldGeometry,
) -> Pose:
    """``template`` as in the team file (as if playing left); ``side_sign`` -1 left, +1 right."""
    y_abs = abs(template.y_m) if template.y_m != 0 else field.half_width_m
    if ball_y_m > 0:
        y = -y_abs
    elif ball_y_m < 0:
        y = y_abs
    else:
        y = math.copysign(y_abs, template.y_m) if template.y_m != 0 else -y_abs
    yaw = math.pi / 2.0 if y < 0 else -math.pi / 2.0  # facing into the field
    base_x = side_sign * field.penalty_mark_x_m
    step = field.penalty_offset_m
    for k in range(0, 20):
        offset = (k + 1) // 2 * step * (1 if k % 2 else -1)  # 0, +s, -s, +2s, ...
        x = base_x + side_sign * offset
        if abs(x) > field.half_length_m:
            continue
        if all(math.hypot(x - ox, y - oy) >= step for ox, oy in occupied):
            return Pose(x_m=x, y_m=y, yaw_rad=yaw)
    return Pose(x_m=base_x, y_m=y, yaw_rad=yaw)


def removal_commands(robot: RobotId, pose: Pose) -> list[WorldCommand]:
    return [
        TeleportRobot(robot=robot, pose=pose),
        SetLimp(robot=robot, limp=True),
    ]


def return_commands(robot: RobotId) -> list[WorldCommand]:
    return [SetLimp(robot=robot, limp=False)]


def red_card_commands(robot: RobotId) -> list[WorldCommand]:
    return [RemoveRobot(robot=robot)]


def penalised_in_field(
    snapshot: WorldSnapshot,
    penalised: frozenset[RobotId],
    field: FieldGeometry,
    carried: Mapping[RobotId, Vec2],
) -> list[RobotId]:
    """Penalised robots (not sent off) back on the field, which the league's referee shows a
    yellow card, removes again and, the second time, sends off (hlvs_webots referee.py:
    1287-1302, ``check_team_penalized_in_field``, with ``send_penalty`` 894-897 letting the new
    penalty through). The league reads the feet's contacts (one on the field or a line is in);
    here the torso, more than a line's width inside the field, so that a robot standing at its
    re-entry spot on a touch line is not in; nor is one standing where the referee put it
    (``carried``: within a robot's radius), should its team's re-entry pose be on the field."""
    inside_x = field.half_length_m - field.line_width_m
    inside_y = field.half_width_m - field.line_width_m
    found = []
    for robot in snapshot.robots:
        if robot.id not in penalised or robot.removed:
            continue
        x, y = robot.position[0], robot.position[1]
        if abs(x) >= inside_x or abs(y) >= inside_y:
            continue
        put = carried.get(robot.id)
        if put is not None and math.hypot(x - put[0], y - put[1]) < field.robot_radius_m:
            continue
        found.append(robot.id)
    return found
