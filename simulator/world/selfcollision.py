"""Self-collision of a robot: which pairs of its own links never collide.

Every link of a robot collides with every other link of the same robot except:

1. a link and its *collision parent*: the nearest ancestor body that has collision geoms (bodies
   without collision geoms, the small servo-horn links between two joints of a hip or a
   shoulder, are skipped, so the links they join count as adjacent);
2. links of one chain (one an ancestor of the other) whose collision shapes touch, or come
   within :data:`NEAR_M` of each other, with every joint at zero or in the model's standing pose
   (coarse collision shapes of team models that overlap or all but meet at a joint: the
   Wolfgang's head hull is half a millimetre above its torso hull, which a real head clears when
   it looks down). Links of different chains (the two legs) always collide, whatever their
   shapes: a shape made to reach the other leg cannot switch the legs' collisions off (the
   model check refuses shapes that overlap across chains). The built-in robots, whose shapes
   are the league's own, keep the exclusion of every touching pair (their hands hang against
   their thighs at zero).

MuJoCo itself leaves out a body and its parent. The rule is applied the same way to the built-in
robots and to team models (computed from the model alone, once per model per process).
"""

from __future__ import annotations

import threading

import mujoco
import numpy as np

from simulator.world.robots import AnyRobotModel
from simulator.world.robots.humanoid import RobotModel

_PREFIX = "selfcheck"
NEAR_M = 0.005
"""Shapes this close in the reference poses count as touching (rule 2)."""
_CACHE: dict[str, tuple[tuple[str, str], ...]] = {}
_LOCK = threading.Lock()


def excluded_pairs(model: AnyRobotModel) -> tuple[tuple[str, str], ...]:
    """Body name pairs (without the robot prefix, ``torso`` style) that do not collide."""
    with _LOCK:
        cached = _CACHE.get(model.name)
        if cached is None:
            cached = _CACHE[model.name] = _compute(model)
        return cached


def exclude_xml(model: AnyRobotModel, prefix: str) -> str:
    """``<exclude>`` elements (for the world's ``<contact>`` section) of one robot."""
    return "".join(
        f'<exclude body1="{prefix}/{a}" body2="{prefix}/{b}"/>' for a, b in excluded_pairs(model)
    )


def _standalone(model: AnyRobotModel) -> mujoco.MjModel:
    parts = model.mjcf(prefix=_PREFIX, rgba="1 0 0 1", contype=1, conaffinity=1, pose=(0, 0, 0))
    xml = (
        '<mujoco><compiler angle="radian" autolimits="true"/>'
        f"<asset>{parts.assets}</asset><worldbody>{parts.body}</worldbody></mujoco>"
    )
    return mujoco.MjModel.from_xml_string(xml)


def _compute(model: AnyRobotModel) -> tuple[tuple[str, str], ...]:
    built_in = isinstance(model, RobotModel)
    mj = _standalone(model)
    colliding = np.zeros(mj.nbody, dtype=bool)
    for g in range(mj.ngeom):
        if mj.geom_contype[g] or mj.geom_conaffinity[g]:
            colliding[mj.geom_bodyid[g]] = True
    pairs: set[tuple[int, int]] = set()
    for body in range(1, mj.nbody):
        if not colliding[body]:
            continue
        parent = int(mj.body_parentid[body])
        while parent > 0 and not colliding[parent]:
            parent = int(mj.body_parentid[parent])
        if parent > 0 and parent != mj.body_parentid[body]:
            pairs.add((min(body, parent), max(body, parent)))
    mj.geom_margin[:] = NEAR_M  # contacts are reported for shapes closer than the margin
    data = mujoco.MjData(mj)
    joints = [mj.joint(f"{_PREFIX}/{name}") for name in model.motor_names]
    for pose in (np.zeros(len(joints)), np.asarray(model.standing_pose_rad, dtype=float)):
        for joint, value in zip(joints, pose, strict=True):
            data.qpos[joint.qposadr[0]] = value
        mujoco.mj_forward(mj, data)
        for g1, g2 in data.contact.geom[: data.ncon].tolist():
            a, b = int(mj.geom_bodyid[g1]), int(mj.geom_bodyid[g2])
            if a != b and (built_in or _ancestor(mj, a, b) or _ancestor(mj, b, a)):
                pairs.add((min(a, b), max(a, b)))
    start = len(_PREFIX) + 1
    return tuple(sorted((mj.body(a).name[start:], mj.body(b).name[start:]) for a, b in pairs))


def _ancestor(mj: mujoco.MjModel, ancestor: int, body: int) -> bool:
    """Whether ``ancestor`` is ``body``'s parent, grandparent ..."""
    while body > 0:
        body = int(mj.body_parentid[body])
        if body == ancestor:
            return True
    return False
