"""Checks a team robot model against the rule book of its size class, as the league's model
verifier did before a competition.

Measured with every joint at zero (the upright posture of the rules) and the lowest point on the
ground: ``H`` the robot's height, ``Hleg`` from the ground to the first joint of the leg (the hip),
``Hhead`` from the shoulder joint to the top, ``Htop = H - Hleg`` the upper body, ``Harm`` per
arm chain (each link tagged ``arm`` with its subtree) from that chain's first joint to the
farthest point of its own arm and hand, the longest chain reported, and each foot's length and
width. The bounds are the Humanoid League's (law 4, robot dimensions; the height range is the
league reference's), cameras at most two with a horizontal field of view of at most 180 degrees.

The committee's physics checks: every motor's servo from the league catalogue (at most its
figures; free-form servos and gains are warnings in friendlies, errors in official matches,
:mod:`.servos`), every motor joint with a range, and each link's mass and inertia plausible for
its size: density (mass over the volume of the link's shapes' bounding box) within
``DENSITY_KG_M3`` and each principal inertia between ``MIN_INERTIA_KG_M2`` and the mass times
the squared diagonal of that box (no point of the link is farther from its centre).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields, replace

import mujoco
import numpy as np

from contracts import JSONObject, to_data
from simulator.errors import ModelProblem
from simulator.world.robots.team.model import TeamRobotModel
from simulator.world.robots.team.servos import servo_problems

HEIGHT_M = {"kid": (0.40, 1.00), "adult": (1.00, 2.00)}
LEG_RATIO = (0.35, 0.70)  # Hleg / H
HEAD_RATIO = (0.05, 0.25)  # Hhead / H
ARM_TOP_RATIO = 1.2  # Harm <= 1.2 Htop
FOOT_AREA_H2 = 2.2 / 32  # foot length x width <= 2.2 H^2 / 32
FOOT_ASPECT = 2.5  # foot length / width
MAX_CAMERAS = 2
MAX_FOV_RAD = math.pi
MARKER = "/visual:marker"  # the team-colour marker we add is not part of the robot
DENSITY_KG_M3 = (50.0, 10000.0)  # foam-light shells to steel, over the bounding box volume
MIN_INERTIA_KG_M2 = 1e-8
FRAME_KG = 1e-5  # lighter links are frames (camera, IMU), not parts


@dataclass(frozen=True, slots=True)
class Measurements:
    size_class: str  # the class the manifest declares ("kid", "adult"), whose rules were applied
    height_m: float
    leg_m: float
    head_m: float
    top_m: float
    arm_m: float  # the longest arm chain
    foot_length_m: float
    foot_width_m: float
    mass_kg: float
    cameras: int
    max_fov_rad: float
    motors: int
    arm_chains_m: dict[str, float] = field(default_factory=dict)  # first link -> reach
    servos: dict[str, str] = field(default_factory=dict)  # motor -> catalogue id ("" free)

    def rounded(self) -> Measurements:
        """These measurements with lengths, masses and angles rounded to 4 decimals (0.1 mm),
        as ``hlvs check`` shows them."""
        return replace(
            self,
            **{f.name: round(getattr(self, f.name), 4)
               for f in fields(self) if isinstance(getattr(self, f.name), float)},
            arm_chains_m={k: round(v, 4) for k, v in self.arm_chains_m.items()},
            servos=dict(self.servos),
        )  # fmt: skip

    def to_json(self) -> JSONObject:
        """:meth:`rounded` as JSON (``hlvs check --json``), in field order."""
        data: JSONObject = to_data(self.rounded())
        return data


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
    chains = _arm_chains(robot, model, data)
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
        size_class=robot.field_class,
        height_m=height,
        leg_m=leg,
        head_m=head,
        top_m=height - leg,
        arm_m=max(chains.values(), default=0.0),
        foot_length_m=foot_length,
        foot_width_m=foot_width,
        mass_kg=float(model.body_subtreemass[1]),
        cameras=len(cams),
        max_fov_rad=max((c.fov_rad for c in cams), default=0.0),
        motors=len(robot.motors),
        arm_chains_m=chains,
        servos={m.name: m.servo for m in robot.motors},
    )


def _arm_chains(
    robot: TeamRobotModel, model: mujoco.MjModel, data: mujoco.MjData
) -> dict[str, float]:
    """Per arm chain (a link tagged ``arm`` whose parent is not): the distance from its first
    joint to the farthest corner of the arm and hand shapes in its own subtree."""
    arm_links = [k for k, v in robot.manifest.parts.items() if v == "arm"]
    bodies = {}
    for link in arm_links:
        try:
            bodies[link] = model.body(f"r/link:{link}").id
        except KeyError:
            continue
    roots = {
        link: b
        for link, b in bodies.items()
        if not any(_subtree_of(model, b, other) for other in bodies.values() if other != b)
    }
    chains: dict[str, float] = {}
    for link, root in roots.items():
        anchor = _first_anchor(model, data, root)
        reach = 0.0
        for g in range(model.ngeom):
            name = model.geom(g).name
            if not any(name.startswith(f"r/{part}:") for part in ("arm", "hand")):
                continue
            if not _subtree_of(model, int(model.geom_bodyid[g]), root):
                continue
            distances = np.linalg.norm(_corners(model, data, g) - anchor, axis=1)
            reach = max(reach, float(distances.max()))
        chains[link] = reach
    return chains


def _first_anchor(model: mujoco.MjModel, data: mujoco.MjData, root: int) -> np.ndarray:
    """The anchor of the first joint at or below ``root`` (depth first), else the body origin."""
    stack = [root]
    while stack:
        body = stack.pop(0)
        if model.body_jntnum[body] > 0:
            anchor: np.ndarray = data.xanchor[int(model.body_jntadr[body])]
            return anchor
        stack.extend(b for b in range(model.nbody) if model.body_parentid[b] == body and b != body)
    origin: np.ndarray = data.xpos[root]
    return origin


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


def check(
    robot: TeamRobotModel, *, official: bool = False
) -> tuple[Measurements, list[ModelProblem]]:
    """The measurements and every rule they break (value, limit and rule in each message);
    warnings (``severity``) for what friendlies allow and ``official`` matches refuse."""
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
    problems.extend(servo_problems(robot.manifest, official=official))
    for motor in robot.motors:
        if not motor.lower_rad < motor.upper_rad:
            bad(
                f"joint range of {motor.name}",
                f"[{motor.lower_rad:g}, {motor.upper_rad:g}] rad: every motor joint needs its "
                "range (lower < upper): in the model file, or, where the file has none, as "
                f'"range_rad": [lower, upper] (rad) in this motor\'s entry of /motors',
            )
    problems.extend(_inertia_problems(robot, source))
    problems.extend(robot.notes)
    return m, problems


def _inertia_problems(robot: TeamRobotModel, source: str) -> list[ModelProblem]:
    """Links whose mass or inertia does not fit their shapes (see the module's rule)."""
    model = _standalone(robot)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    out: list[ModelProblem] = []
    for body in range(1, model.nbody):
        if not model.body(body).name.startswith("r/link:"):
            continue  # the frame we add around the model's root
        mass = float(model.body_mass[body])
        if mass <= FRAME_KG:
            continue  # a frame (camera, IMU) without mass of its own
        name = model.body(body).name.removeprefix("r/").removeprefix("link:")
        inertia = model.body_inertia[body]
        geoms = [
            g
            for g in range(model.ngeom)
            if model.geom_bodyid[g] == body and not model.geom(g).name.endswith(MARKER)
        ]
        top = math.inf
        if geoms:
            rot = data.xmat[body].reshape(3, 3)
            corners = [(_corners(model, data, g) - data.xpos[body]) @ rot for g in geoms]
            local = np.concatenate(corners)
            extent = local.max(axis=0) - local.min(axis=0)
            density = mass / float(np.prod(np.maximum(extent, 1e-3)))
            diagonal = float(np.linalg.norm(extent))
            top = mass * diagonal * diagonal
            low, high = DENSITY_KG_M3
            if not low <= density <= high:
                size = " x ".join(f"{v:.3f}" for v in extent)
                out.append(ModelProblem(
                    source=source, where=f"mass of {name}",
                    reason=f"{mass:.4g} kg in a {size} m box is {density:.0f} kg/m^3, outside "
                    f"{low:g}-{high:g} kg/m^3 (rule: link masses plausible for their size)",
                ))  # fmt: skip
        if inertia.min() < MIN_INERTIA_KG_M2 or inertia.max() > top:
            bound = f"{top:.3g} kg m^2 (mass x squared size)" if geoms else "-"
            out.append(ModelProblem(
                source=source, where=f"inertia of {name}",
                reason=f"principal inertia {', '.join(f'{v:.3g}' for v in inertia)} kg m^2 of "
                f"{mass:.4g} kg is outside {MIN_INERTIA_KG_M2:g} - {bound} (rule: link "
                "inertias plausible for their size)",
            ))  # fmt: skip
    return out
