"""Placing a set play's ball when its sub-phase 0 ends, clearing the spot as the league does.

Through sub-phase 0 the ball is left where it is (robots may touch it then); when sub-phase 0
ends (and again after a RETAKE) the ball is placed on the set play's spot, as the league's
referee places it (hlvs_webots ``controllers/referee/referee.py:2425-2430`` calling
``game_interruption_place_ball``, 1874-1903). While a robot stands closer than the placement
safety distance (0.5 m kid, 1 m adult: ``field.py:32``) to the spot, up to four measures are
taken in turn, each only while a robot is still near:

1. penalised robots near the spot are put at their re-entry spot again (1794-1798; their
   penalty time runs on);
2. fallen robots near the spot are penalised (INCAPABLE) and removed (1800-1806; the league's
   loop penalises every fallen robot at this point, near the spot or not: here only those the
   function's name and comment speak of, the ones near the spot);
3. other spots are tried, the first free one inside the field is taken (1808-1828): for a free
   kick, steps of the safety distance towards the goal the set-play team attacks, then across
   the field (away from the nearer touch line first), then back; for a throw-in, along the
   touch line towards that goal, then the other way; none for the other set plays;
4. robots still near are pushed away from the spot along the line from the spot through them,
   the first multiple (1 to 5) of the safety distance clear of every other robot (1841-1872;
   their posture and heading are kept).

Distances are measured from each robot's torso, as every other rule of this referee measures
them (the league measures from the centre of mass of its Darwin-OP, within a few centimetres).
"""

from __future__ import annotations

import math

from contracts import Pose, RobotId
from referee.gamecontroller import Penalty, SecondaryState
from referee.gamecontroller.machine import SetPlay
from referee.judgement import RefereeCore, apply_decisions, reentry_pose
from referee.rules.base import Decision, PenalizeRobot
from referee.snapshot import TeleportRobot, Vec2, WorldCommand, WorldSnapshot

PLACEMENT_STEPS = 5  # referee_config.yaml GAME_INTERRUPTION_PLACEMENT_NB_STEPS


def _distance(a: Vec2, b: Vec2) -> float:
    return math.hypot(a[0] - b[0], a[1] - b[1])


def alternative_spots(
    kind: SecondaryState, spot: Vec2, attack_sign: float, safety_m: float
) -> list[Vec2]:
    """The other spots tried in order (hlvs_webots referee.py:1808-1828): ``attack_sign`` is
    the sign of x of the goal the set-play team attacks."""
    x, y = spot
    dx = attack_sign * safety_m
    dy = (-1.0 if y > 0 else 1.0) * safety_m
    spots: list[Vec2] = []
    if kind in (SecondaryState.DIRECT_FREEKICK, SecondaryState.INDIRECT_FREEKICK):
        for k in range(1, PLACEMENT_STEPS + 1):
            spots += [(x + k * dx, y), (x, y + k * dy), (x, y - k * dy), (x - k * dx, y)]
    elif kind is SecondaryState.THROW_IN:
        spots += [(x + k * dx, y) for k in range(1, PLACEMENT_STEPS + 1)]
        spots += [(x - k * dx, y) for k in range(1, PLACEMENT_STEPS + 1)]
    return spots


def pushed_away(
    where: dict[RobotId, Vec2], spot: Vec2, safety_m: float
) -> dict[RobotId, Vec2]:
    """Step 4 (hlvs_webots referee.py:1841-1872): each robot nearer than ``safety_m`` to
    ``spot`` (blue first, then red, by number) moves along the line from the spot through it
    to the first multiple of ``safety_m`` from the spot that is ``safety_m`` clear of every
    other robot (where they stand then); one with no such place within five stays. Returns the
    robots moved and their new places (``where`` is updated too)."""
    moved: dict[RobotId, Vec2] = {}
    order = sorted(where, key=lambda r: (r.team.value != "blue", r.number))
    for robot in order:
        here = where[robot]
        distance = _distance(here, spot)
        if distance >= safety_m:
            continue
        if distance < 0.001:
            ux, uy = 1.0, 0.0
        else:
            ux, uy = (here[0] - spot[0]) / distance, (here[1] - spot[1]) / distance
        others = [p for r, p in where.items() if r != robot]
        for k in range(1, PLACEMENT_STEPS + 1):
            there = (spot[0] + ux * safety_m * k, spot[1] + uy * safety_m * k)
            if all(_distance(o, there) >= safety_m for o in others):
                where[robot] = moved[robot] = there
                break
    return moved


def place_set_play_ball(
    ref: RefereeCore, snapshot: WorldSnapshot, play: SetPlay, spot: Vec2
) -> list[WorldCommand]:
    """Sub-phase 0 of ``play`` ended: clear ``spot`` and place the ball (on it, or on the
    other spot taken). Returns the world commands; logs what was done."""
    field = ref.field
    safety = field.placement_safety_m
    now = snapshot.sim_time_ms
    robots = {
        r.id: r for r in snapshot.robots
        if not r.removed and r.id.number in ref.gc.teams[r.id.team].robots
    }  # fmt: skip
    where: dict[RobotId, Vec2] = {rid: (r.position[0], r.position[1]) for rid, r in robots.items()}
    commands: list[WorldCommand] = []

    def near(point: Vec2) -> list[RobotId]:
        return [rid for rid, p in where.items() if _distance(p, point) < safety]

    target = spot
    penalised = set(ref.gc.penalised())
    for step in (1, 2, 3, 4):
        close = near(target)
        if not close:
            break
        if step == 1:
            for robot in (r for r in close if r in penalised):
                taken = [p for r, p in where.items() if r != robot]
                pose = reentry_pose(ref, robot, snapshot, taken)
                where[robot] = ref.book.carried[robot] = (pose.x_m, pose.y_m)
                commands.append(TeleportRobot(robot=robot, pose=pose))
                ref.log.info(now, f"{robot} (penalised) put at its re-entry spot again to place "
                             "the ball.")  # fmt: skip
        elif step == 2:
            fallen = [r for r in close if robots[r].fallen and r not in penalised]
            decisions: list[Decision] = [
                PenalizeRobot(r, Penalty.PICKUP_OR_INCAPABLE, "fallen close to the ball's spot")
                for r in fallen
            ]
            placed = apply_decisions(ref, decisions, snapshot) if decisions else []
            for command in placed:
                if isinstance(command, TeleportRobot):
                    where[command.robot] = (command.pose.x_m, command.pose.y_m)
            commands += placed
        elif step == 3:
            attack_sign = 1.0 if play.team is ref.left_team else -1.0
            for other in alternative_spots(play.kind, target, attack_sign, safety):
                x, y = other
                inside = abs(x) <= field.half_length_m and abs(y) <= field.half_width_m
                if inside and not near(other):
                    ref.log.info(now, f"Ball's spot ({target[0]:.2f}, {target[1]:.2f}) taken by "
                                 f"robots; placed at ({x:.2f}, {y:.2f}).")  # fmt: skip
                    target = other
                    break
        else:
            for robot, (x, y) in pushed_away(where, target, safety).items():
                yaw = robots[robot].yaw_rad
                commands.append(TeleportRobot(robot=robot, pose=Pose(x_m=x, y_m=y, yaw_rad=yaw)))
                ref.log.info(now, f"{robot} moved to ({x:.2f}, {y:.2f}), away from the ball's "
                             "spot.")  # fmt: skip
    ref.set_play_spot = target
    commands.append(ref.ball_at(*target))
    return commands
