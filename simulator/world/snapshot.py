"""World -> :class:`referee.snapshot.WorldSnapshot`, with numpy gathers over precomputed indices.

Contacts are classified per robot as bit masks of body parts (ground = the turf only, ball) and
robot pairs; masks become frozensets through a precomputed table.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import mujoco
import numpy as np
import numpy.typing as npt

from referee.snapshot import BallState, BodyPart, RobotId, RobotState, WorldSnapshot
from simulator.world.indices import FOOT_BIT, PARTS, WorldIndex

FALLEN_TILT_COS = 0.5  # torso z axis more than 60 degrees from vertical
_PART_SETS: tuple[frozenset[BodyPart], ...] = tuple(
    frozenset(p for i, p in enumerate(PARTS) if mask & (1 << i)) for mask in range(1 << len(PARTS))
)


@dataclass(frozen=True, slots=True)
class Contacts:
    ground: npt.NDArray[np.int64]  # per robot: part bits touching the turf
    ball: npt.NDArray[np.int64]  # per robot: part bits touching the ball
    pairs: list[tuple[int, int]]  # robot numbers in contact (each pair once, sorted)


def classify_contacts(data: mujoco.MjData, index: WorldIndex, n_robots: int) -> Contacts:
    ground = np.zeros(n_robots, dtype=np.int64)
    ball = np.zeros(n_robots, dtype=np.int64)
    ncon = data.ncon
    if ncon == 0 or n_robots == 0:
        return Contacts(ground=ground, ball=ball, pairs=[])
    geom = data.contact.geom[:ncon]
    g1, g2 = geom[:, 0], geom[:, 1]
    r1, r2 = index.geom_robot[g1], index.geom_robot[g2]
    b1, b2 = index.geom_part_bit[g1], index.geom_part_bit[g2]
    for other, robots, bits in ((g2, r1, b1), (g1, r2, b2)):
        on_turf = (other == index.turf_geom) & (robots >= 0)
        if on_turf.any():
            np.bitwise_or.at(ground, robots[on_turf], bits[on_turf])
        on_ball = (other == index.ball_geom) & (robots >= 0)
        if on_ball.any():
            np.bitwise_or.at(ball, robots[on_ball], bits[on_ball])
    between = (r1 >= 0) & (r2 >= 0) & (r1 != r2)
    pairs: list[tuple[int, int]] = []
    if between.any():
        lo = np.minimum(r1[between], r2[between])
        hi = np.maximum(r1[between], r2[between])
        pairs = sorted({(int(a), int(b)) for a, b in zip(lo.tolist(), hi.tolist(), strict=True)})
    return Contacts(ground=ground, ball=ball, pairs=pairs)


def ball_toucher(data: mujoco.MjData, index: WorldIndex) -> int:
    """Robot number touching the ball in the current contacts (lowest number), or -1."""
    ncon = data.ncon
    if ncon == 0:
        return -1
    geom = data.contact.geom[:ncon]
    hit = (geom[:, 0] == index.ball_geom) | (geom[:, 1] == index.ball_geom)
    if not hit.any():
        return -1
    robots = index.geom_robot[geom[hit].ravel()]
    robots = robots[robots >= 0]
    return int(robots.min()) if robots.size else -1


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
    qpos = data.qpos
    pos = qpos[index.root_xyz].tolist()
    quat = qpos[index.root_quat]
    w, x, y, z = quat[:, 0], quat[:, 1], quat[:, 2], quat[:, 3]
    yaw = np.arctan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z)).tolist()
    upright = (1.0 - 2.0 * (x * x + y * y)).tolist()
    com = data.subtree_com[index.torso_bodies].tolist()
    com_vel = data.sensordata[index.com_velocity].tolist()
    hull = data.xpos[index.hull_bodies][:, :, :2].tolist()
    contacts = classify_contacts(data, index, n)
    ground = contacts.ground.tolist()
    ball_bits = contacts.ball.tolist()
    touching: list[set[RobotId]] = [set() for _ in range(n)]
    for a, b in contacts.pairs:
        touching[a].add(robot_ids[b])
        touching[b].add(robot_ids[a])
    robots = []
    for i, robot_id in enumerate(robot_ids):
        gbits = ground[i]
        robots.append(
            RobotState(
                id=robot_id,
                position=tuple(pos[i]),
                yaw_rad=yaw[i],
                center_of_mass=tuple(com[i]),
                velocity=tuple(com_vel[i]),
                ground_contacts=_PART_SETS[gbits],
                ball_contacts=_PART_SETS[ball_bits[i]],
                robot_contacts=frozenset(touching[i]),
                hull_points=tuple(tuple(p) for p in hull[i]),
                fallen=bool(gbits & ~FOOT_BIT) or upright[i] < FALLEN_TILT_COS,
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
