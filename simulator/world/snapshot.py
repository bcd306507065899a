"""World -> :class:`referee.snapshot.WorldSnapshot`, with numpy gathers over precomputed indices.

Contacts are classified per robot as bit masks of body parts (ground = the turf only, ball) and
robot pairs; masks become frozensets through a precomputed table.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import mujoco
import numpy as np
import numpy.typing as npt

from contracts.ids import RobotId
from referee.snapshot import BallState, BodyPart, RobotState, WorldSnapshot
from simulator.world.indices import (
    FOOT_BIT,
    KIND_BALL,
    KIND_ROBOT,
    KIND_TURF,
    KINDS,
    PART_SLOTS,
    PARTS,
    WorldIndex,
)

FALLEN_TILT_COS = 0.5  # torso z axis more than 60 degrees from vertical
_NOBODY: frozenset[RobotId] = frozenset()
_PART_SETS: tuple[frozenset[BodyPart], ...] = tuple(
    frozenset(p for i, p in enumerate(PARTS) if mask & (1 << i)) for mask in range(1 << len(PARTS))
)


@dataclass(frozen=True, slots=True)
class Contacts:
    ground: npt.NDArray[Any]  # per robot: part bits touching the turf
    ball: npt.NDArray[Any]  # per robot: part bits touching the ball
    pairs: list[tuple[int, int]]  # robot numbers in contact (each pair once, sorted)


def classify_contacts(data: mujoco.MjData, index: WorldIndex, n_robots: int) -> Contacts:
    """One pass over the contact list: each side of a contact that is a robot geom gets the code
    (robot, kind of the geom on the other side: turf, ball, robot; part), counted by bincount."""
    ncon = data.ncon
    if ncon == 0 or n_robots == 0:
        zeros = np.zeros(n_robots, dtype=np.int64)
        return Contacts(ground=zeros, ball=zeros.copy(), pairs=[])
    geom = data.contact.geom[:ncon]
    mine = index.geom_code[geom.ravel()]
    other = index.geom_kind_code[geom[:, ::-1].ravel()]
    valid = (mine >= 0) & (other > 0)
    counts = np.bincount(mine[valid] + other[valid], minlength=n_robots * KINDS * PART_SLOTS)
    bits = np.packbits(
        counts.reshape(n_robots, KINDS, PART_SLOTS) > 0, axis=-1, bitorder="little"
    ).reshape(n_robots, KINDS)
    pairs: list[tuple[int, int]] = []
    if bits[:, KIND_ROBOT].any():
        robots = index.geom_robot[geom]
        between = (robots[:, 0] >= 0) & (robots[:, 1] >= 0) & (robots[:, 0] != robots[:, 1])
        pairs = sorted({(int(a), int(b)) for a, b in np.sort(robots[between], axis=1).tolist()})
    return Contacts(ground=bits[:, KIND_TURF], ball=bits[:, KIND_BALL], pairs=pairs)


def ball_toucher(data: mujoco.MjData, index: WorldIndex) -> int:
    """Robot number touching the ball in the last substep (lowest number), or -1.

    Reads one contact sensor per robot (MuJoCo counts the contacts in C), which is much cheaper
    than scanning the contact list in Python every step.
    """
    if index.ball_touch.size == 0:
        return -1
    touching = np.flatnonzero(data.sensordata[index.ball_touch])
    return int(touching[0]) if touching.size else -1


def build_snapshot(
    *,
    data: mujoco.MjData,
    index: WorldIndex,
    robot_ids: Sequence[RobotId],
    sim_time_ms: int,
    limp: Sequence[bool],
    removed: Sequence[bool],
    last_toucher: RobotId | None,
    last_touch_ms: int | None,
) -> WorldSnapshot:
    n = len(robot_ids)
    q = index.ball_qpos
    d = index.ball_dof
    ball = BallState(
        position=tuple(data.qpos[q : q + 3].tolist()),
        velocity=tuple(data.qvel[d : d + 3].tolist()),
    )
    if n == 0:
        return WorldSnapshot(sim_time_ms=sim_time_ms, ball=ball, robots=())
    # one (n, 21) table, one tolist: x y z | yaw upright | com xyz | com velocity xyz | hull 4 x xy
    table = np.empty((n, 21))
    table[:, 0:3] = data.qpos[index.root_xyz]
    rot = data.xmat[index.torso_bodies]  # row-major 3x3
    table[:, 3] = np.arctan2(rot[:, 3], rot[:, 0])
    table[:, 4] = rot[:, 8]  # z of the torso's up axis
    table[:, 5:8] = data.subtree_com[index.torso_bodies]
    table[:, 8:11] = data.sensordata[index.com_velocity]
    table[:, 11:21] = 0.0
    table[:, 11:19] = data.xpos[index.hull_bodies][:, :, :2].reshape(n, 8)
    rows = table.tolist()
    contacts = classify_contacts(data, index, n)
    ground = contacts.ground.tolist()
    ball_bits = contacts.ball.tolist()
    touching: list[frozenset[RobotId]] = [_NOBODY] * n
    for a, b in contacts.pairs:
        touching[a] = touching[a] | {robot_ids[b]}
        touching[b] = touching[b] | {robot_ids[a]}
    robots = []
    for i, robot_id in enumerate(robot_ids):
        r = rows[i]
        gbits = ground[i]
        robots.append(
            RobotState(
                id=robot_id,
                position=(r[0], r[1], r[2]),
                yaw_rad=r[3],
                center_of_mass=(r[5], r[6], r[7]),
                velocity=(r[8], r[9], r[10]),
                ground_contacts=_PART_SETS[gbits],
                ball_contacts=_PART_SETS[ball_bits[i]],
                robot_contacts=touching[i],
                hull_points=((r[11], r[12]), (r[13], r[14]), (r[15], r[16]), (r[17], r[18])),
                fallen=bool(gbits & ~FOOT_BIT) or r[4] < FALLEN_TILT_COS,
                limp=limp[i],
                removed=removed[i],
            )
        )
    return WorldSnapshot(
        sim_time_ms=sim_time_ms,
        ball=ball,
        robots=tuple(robots),
        last_ball_toucher=last_toucher,
        last_ball_touch_ms=last_touch_ms,
    )
