"""Checks a team robot model against the rule book of its size class, as the league's model
verifier did before a competition.

Measured with every joint at zero (the upright posture of the rules) and the lowest point on the
ground: ``H`` the robot's height, ``Hleg`` from the ground to the first joint of the leg (the hip),
``Hhead`` from the shoulder joint to the top, ``Htop = H - Hleg`` the upper body, ``Harm`` from the
shoulder joint to the farthest point of the arm and hand, and each foot's length and width. The
bounds are the Humanoid League's (law 4, robot dimensions; the height range is the league
reference's), cameras at most two with a horizontal field of view of at most 180 degrees.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import mujoco
import numpy as np

from simulator.errors import ModelProblem
from simulator.world.robots.team.model import TeamRobotModel

HEIGHT_M = {"kid": (0.40, 1.00), "adult": (1.00, 2.00)}
LEG_RATIO = (0.35, 0.70)  # Hleg / H
HEAD_RATIO = (0.05, 0.25)  # Hhead / H
ARM_TOP_RATIO = 1.2  # Harm <= 1.2 Htop
FOOT_AREA_H2 = 2.2 / 32  # foot length x width <= 2.2 H^2 / 32
FOOT_ASPECT = 2.5  # foot length / width
MAX_CAMERAS = 2
MAX_FOV_RAD = math.pi
MARKER = "/visual:marker"  # the team-colour marker we add is not part of the robot
TORQUE_PER_WEIGHT_M = 5.0  # a servo stronger than 5 x m g H is a unit mistake (N cm, mN m)


@dataclass(frozen=True, slots=True)
class Measurements:
    height_m: float
    leg_m: float
    head_m: float
    top_m: float
    arm_m: float
    foot_length_m: float
    foot_width_m: float
    mass_kg: float
    cameras: int
    max_fov_rad: float
    motors: int

    def to_json(self) -> dict[str, float | int]:
        return {k: (round(v, 4) if isinstance(v, float) else v) for k, v in asdict(self).items()}


def _standalone(robot: TeamRobotModel) -> mujoco.MjModel:
    parts = robot.mjcf(prefix="r", rgba="1 0 0 1", contype=1, conaffinity=1, pose=(0, 0, 0))
    xml = (
        '<mujoco><compiler angle="radian" autolimits="true"/>'
        f"<asset>{parts.assets}</asset><worldbody>{parts.body}</worldbody></mujoco>"
    )
    return mujoco.MjModel.from_xml_string(xml)


def _corners(model: mujoco.MjModel, data: mujoco.MjData, g: int) -> np.ndarray:
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    centre, half = model.geom_aabb[g][:3], model.geom_aabb[g][3:]
    rot = data.geom_xmat[g].reshape(3, 3)
    out: np.ndarray = data.geom_xpos[g] + (centre + signs * half) @ rot.T
    return out


def _first_joint_of(model: mujoco.MjModel, links: list[str]) -> list[int]:
    """Joint ids of the named links (template names ``r/link:<link>``), where they have one."""
    out = []
    for link in links:
        try:
            body = model.body(f"r/link:{link}")
        except KeyError:
            continue
        if model.body_jntnum[body.id] > 0:
            out.append(int(model.body_jntadr[body.id]))
    return out


def measure(robot: TeamRobotModel) -> Measurements:
    model = _standalone(robot)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    body_geoms = [g for g in range(model.ngeom) if not model.geom(g).name.endswith(MARKER)]
    points = np.concatenate([_corners(model, data, g) for g in body_geoms])
    ground = points[:, 2].min()
    height = float(points[:, 2].max() - ground)
    parts = robot.manifest.parts
    leg_joints = _first_joint_of(model, [k for k, v in parts.items() if v == "leg"])
    arm_joints = _first_joint_of(model, [k for k, v in parts.items() if v == "arm"])
    anchors = data.xanchor
    leg = max((float(anchors[j][2] - ground) for j in leg_joints), default=0.0)
    shoulder_z = max((float(anchors[j][2]) for j in arm_joints), default=float(points[:, 2].max()))
    head = float(points[:, 2].max() - shoulder_z)
    arm = 0.0
    for g in range(model.ngeom):
        name = model.geom(g).name
        if not any(name.startswith(f"r/{part}:") for part in ("arm", "hand")):
            continue
        for j in arm_joints:
            arm = max(
                arm, float(np.linalg.norm(_corners(model, data, g) - anchors[j], axis=1).max())
            )
    foot_length = foot_width = 0.0
    for side in robot.manifest.feet:
        foot = model.body(f"r/link:{side}")
        rot = data.xmat[foot.id].reshape(3, 3)
        pts = [
            (_corners(model, data, g) - data.xpos[foot.id]) @ rot
            for g in range(model.ngeom)
            if model.geom(g).name.startswith("r/foot:")
            and _subtree_of(model, int(model.geom_bodyid[g]), _foot_root(model, foot.id))
        ]
        if pts:
            local = np.concatenate(pts)
            extent = local.max(axis=0) - local.min(axis=0)
            foot_length = max(foot_length, float(max(extent[0], extent[1])))
            foot_width = max(foot_width, float(min(extent[0], extent[1])))
    cams = robot.manifest.cameras
    return Measurements(
        height_m=height,
        leg_m=leg,
        head_m=head,
        top_m=height - leg,
        arm_m=arm,
        foot_length_m=foot_length,
        foot_width_m=foot_width,
        mass_kg=float(model.body_subtreemass[1]),
        cameras=len(cams),
        max_fov_rad=max((c.fov_rad for c in cams), default=0.0),
        motors=len(robot.motors),
    )


def _foot_root(model: mujoco.MjModel, body: int) -> int:
    """The highest ancestor of ``body`` still tagged foot (the ankle link of most models)."""
    root = body
    while True:
        parent = int(model.body_parentid[root])
        geoms = [g for g in range(model.ngeom) if model.geom_bodyid[g] == parent]
        if parent == 0 or not any(model.geom(g).name.startswith("r/foot:") for g in geoms):
            return root
        root = parent


def _subtree_of(model: mujoco.MjModel, body: int, root: int) -> bool:
    while body > 0:
        if body == root:
            return True
        body = int(model.body_parentid[body])
    return False


def check(robot: TeamRobotModel) -> tuple[Measurements, list[ModelProblem]]:
    """The measurements and every rule they break (value, limit and rule in each message)."""
    m = measure(robot)
    source = str(robot.manifest.path)
    problems: list[ModelProblem] = []

    def bad(rule: str, reason: str) -> None:
        problems.append(ModelProblem(source=source, where=rule, reason=reason))

    low, high = HEIGHT_M[robot.field_class]
    if not low <= m.height_m <= high:
        bad(
            "height",
            f"H = {m.height_m:.3f} m is outside {low}-{high} m for the "
            f"{robot.field_class} size class",
        )
    h = m.height_m
    if not LEG_RATIO[0] * h <= m.leg_m <= LEG_RATIO[1] * h:
        bad(
            "leg length",
            f"Hleg = {m.leg_m:.3f} m is outside {LEG_RATIO[0]} H - {LEG_RATIO[1]} H "
            f"= {LEG_RATIO[0] * h:.3f}-{LEG_RATIO[1] * h:.3f} m",
        )
    if not HEAD_RATIO[0] * h <= m.head_m <= HEAD_RATIO[1] * h:
        bad(
            "head size",
            f"Hhead = {m.head_m:.3f} m is outside {HEAD_RATIO[0]} H - "
            f"{HEAD_RATIO[1]} H = {HEAD_RATIO[0] * h:.3f}-{HEAD_RATIO[1] * h:.3f} m",
        )
    if m.arm_m > ARM_TOP_RATIO * m.top_m:
        bad(
            "arm length",
            f"Harm = {m.arm_m:.3f} m is above {ARM_TOP_RATIO} Htop = "
            f"{ARM_TOP_RATIO * m.top_m:.3f} m",
        )
    area = m.foot_length_m * m.foot_width_m
    if area > FOOT_AREA_H2 * h * h:
        bad(
            "foot size",
            f"foot {m.foot_length_m:.3f} x {m.foot_width_m:.3f} m = {area:.4f} m^2 "
            f"is above 2.2 H^2 / 32 = {FOOT_AREA_H2 * h * h:.4f} m^2",
        )
    if m.foot_width_m > 0 and m.foot_length_m / m.foot_width_m > FOOT_ASPECT:
        bad(
            "foot size",
            f"foot length / width = {m.foot_length_m / m.foot_width_m:.2f} is above {FOOT_ASPECT}",
        )
    if m.cameras > MAX_CAMERAS:
        bad("cameras", f"{m.cameras} cameras; at most {MAX_CAMERAS}")
    for i, cam in enumerate(robot.manifest.cameras):
        if cam.fov_rad > MAX_FOV_RAD:
            bad(
                f"/cameras/{i}/fov_rad",
                f"horizontal field of view {cam.fov_rad:.3f} rad "
                f"({math.degrees(cam.fov_rad):.0f} deg) is above {MAX_FOV_RAD:.3f} rad (180 deg)",
            )
    weight_limit = TORQUE_PER_WEIGHT_M * m.mass_kg * 9.81 * h
    for i, motor in enumerate(robot.manifest.motors):
        if motor.max_torque_nm > weight_limit:
            bad(
                f"/motors/{i}/max_torque_nm",
                f"{motor.max_torque_nm} N m for {motor.name} is "
                f"above {weight_limit:.1f} N m (5 x the robot's weight x its height): check the "
                "unit (N m)",
            )
    return m, problems
