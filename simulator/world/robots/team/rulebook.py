"""Checks a team robot model against the rule book of its size class, as the league's model
verifier did before a competition.

Measured with every joint at zero (the upright posture of the rules) and the lowest point on the
ground: ``H`` the robot's height, ``Hleg`` from the ground to the first joint of the leg (the hip),
``Hhead`` from the shoulder joint to the top, ``Htop = H - Hleg`` the upper body, ``Harm`` per
kinematic chain from the torso (each jointed link hanging from the torso, with its subtree)
that carries no foot, whatever its tag in ``parts`` (an arm tagged ``head`` is still measured),
from that chain's first joint to the farthest point of its own shapes, the longest chain
reported, and each foot's length and width. The bounds are the Humanoid League's (law 4, robot
dimensions; the height range is the league reference's), cameras at most two with a horizontal
field of view of at most 180 degrees.

The committee's physics checks: every motor's servo from the league catalogue (at most its
figures; free-form servos and gains are warnings in friendlies, errors in official matches,
:mod:`.servos`), every motor joint with a range, and each link's mass and inertia plausible for
its size: density (mass over the volume of the link's shapes' bounding box) within
``DENSITY_KG_M3`` and each principal inertia between ``MIN_INERTIA_KG_M2`` and the mass times
the squared diagonal of that box (no point of the link is farther from its centre).

What a technical committee checks of the physics, not the declarations (each moving part is a
link with its joint and the links welded to it):

- mass per moving part plausible for its size: at most ``PART_DENSITY_KG_M3`` (solid
  aluminium) over the box around its shapes, for parts above ``DENSE_PART_KG`` (no lead in the
  feet: the densest part of the published robots we measured is 1610 kg/m^3, Booster T1's
  waist; a part is servos, brackets and air);
- the model weighs at least its servos (the catalogue's mass of each motor's servo);
- every moving part that has mass is covered by collision shapes: its centre of mass lies in
  (within ``COVER_MARGIN_M`` of) the collision box of the part itself, of its parent or of one of
  its children (the small servo-horn links between two joints ride inside their neighbour's);
- the links' shapes touch, with every joint at zero and in the standing pose, only where the
  self-collision rule lets them (a parent and its child, or links of one chain,
  :mod:`simulator.world.selfcollision`): shapes that reach another chain would stop collisions
  between the chains' links in the match.
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
from simulator.world.selfcollision import NEAR_M, excluded_pairs
from simulator.world.servos import find_servo

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
PART_DENSITY_KG_M3 = 2700.0
"""At most this (solid aluminium) over the box around a moving part's shapes (see the module)."""
DENSE_PART_KG = 0.1
"""Lighter parts (a bearing, a cross piece) may be denser: the bound applies above this mass."""
COVER_MARGIN_M = 0.01
OVERLAP_M = 0.001
"""Shapes of links of different chains may not overlap by more than this in a reference pose."""


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
    servo_mass_kg: float = 0.0  # the catalogue mass of every motor's servo
    mass_split_kg: dict[str, float] = field(default_factory=dict)  # part -> mass (parts' tags)
    collision_coverage: float = 0.0  # share of the mass in parts covered by collision shapes
    uncovered_parts: tuple[str, ...] = ()  # parts with mass outside every collision box

    def rounded(self) -> Measurements:
        """These measurements with lengths, masses and angles rounded to 4 decimals (0.1 mm),
        as ``hlvs check`` shows them."""
        return replace(
            self,
            **{f.name: round(getattr(self, f.name), 4)
               for f in fields(self) if isinstance(getattr(self, f.name), float)},
            arm_chains_m={k: round(v, 4) for k, v in self.arm_chains_m.items()},
            servos=dict(self.servos),
            mass_split_kg={k: round(v, 4) for k, v in self.mass_split_kg.items()},
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
    parts_table = _moving_parts(model, data)
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
        servo_mass_kg=_servo_mass(robot),
        mass_split_kg=_mass_split(robot, model),
        collision_coverage=_coverage(parts_table),
        uncovered_parts=tuple(p.name for p in parts_table.values() if not p.covered),
    )


def _arm_chains(
    robot: TeamRobotModel, model: mujoco.MjModel, data: mujoco.MjData
) -> dict[str, float]:
    """Per kinematic chain from the torso that carries no foot (the torso: the root and the
    links welded to it; a chain: a jointed link hanging from it, with its subtree), whatever the
    tags of its links: the distance from its first joint to the farthest corner of its shapes."""
    root = model.body("r/torso").id
    torso = {b for b in range(1, model.nbody) if _owner(model, b) == root}
    feet = set()
    for side in robot.manifest.feet:
        try:
            feet.add(model.body(f"r/link:{side}").id)
        except KeyError:
            continue
    chains: dict[str, float] = {}
    for start in range(1, model.nbody):
        if start in torso or int(model.body_parentid[start]) not in torso:
            continue
        if model.body_jntnum[start] == 0:
            continue
        if any(_subtree_of(model, f, start) for f in feet):
            continue  # a leg: measured by the leg and foot rules
        anchor = _first_anchor(model, data, start)
        reach = 0.0
        for g in range(model.ngeom):
            if model.geom(g).name.endswith(MARKER):
                continue
            if not _subtree_of(model, int(model.geom_bodyid[g]), start):
                continue
            distances = np.linalg.norm(_corners(model, data, g) - anchor, axis=1)
            reach = max(reach, float(distances.max()))
        if reach > 0.0:
            chains[_link_name(model, start)] = reach
    return chains


def _link_name(model: mujoco.MjModel, body: int) -> str:
    name: str = model.body(body).name
    return name.removeprefix("r/").removeprefix("link:")


def _owner(model: mujoco.MjModel, body: int) -> int:
    """The moving part ``body`` belongs to: itself if it has a joint, else the nearest ancestor
    with one (the root's free joint included)."""
    while model.body_jntnum[body] == 0 and model.body_parentid[body] != 0:
        body = int(model.body_parentid[body])
    return body


@dataclass(frozen=True, slots=True)
class _Part:
    name: str
    mass_kg: float
    com: np.ndarray  # world, zero pose
    box: tuple[np.ndarray, np.ndarray] | None  # collision box (owner frame), None if none
    shapes: tuple[np.ndarray, np.ndarray] | None  # box around every shape, visual ones too
    parent: int  # owner id of the parent part (0: none)
    covered: bool = True


def _moving_parts(model: mujoco.MjModel, data: mujoco.MjData) -> dict[int, _Part]:
    """Owner body id -> its moving part: mass, centre of mass, collision box, and whether the
    centre of mass lies in its own, its parent's or a child's collision box."""
    members: dict[int, list[int]] = {}
    for b in range(1, model.nbody):
        name = model.body(b).name
        if name == "r/torso" or name.startswith("r/link:"):
            members.setdefault(_owner(model, b), []).append(b)
    boxes: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # collision shapes
    shapes: dict[int, tuple[np.ndarray, np.ndarray]] = {}  # every shape, visual too
    for g in range(model.ngeom):
        if model.geom(g).name.endswith(MARKER):
            continue
        owner = _owner(model, int(model.geom_bodyid[g]))
        rot = data.xmat[owner].reshape(3, 3)
        local = (_corners(model, data, g) - data.xpos[owner]) @ rot
        collides = bool(model.geom_contype[g] or model.geom_conaffinity[g])
        for into in (boxes, shapes) if collides else (shapes,):
            lo, hi = local.min(axis=0), local.max(axis=0)
            if owner in into:
                lo, hi = np.minimum(lo, into[owner][0]), np.maximum(hi, into[owner][1])
            into[owner] = (lo, hi)
    parts: dict[int, _Part] = {}
    for owner, bodies in members.items():
        mass = float(sum(model.body_mass[b] for b in bodies))
        com = (
            sum(model.body_mass[b] * data.xipos[b] for b in bodies) / mass
            if mass > 0
            else data.xpos[owner].copy()
        )
        parent = int(model.body_parentid[owner])
        parts[owner] = _Part(
            name=_link_name(model, owner),
            mass_kg=mass,
            com=np.asarray(com, dtype=float),
            box=boxes.get(owner),
            shapes=shapes.get(owner),
            parent=_owner(model, parent) if parent > 0 else 0,
        )

    def inside(point: np.ndarray, owner: int) -> bool:
        if owner not in boxes:
            return False
        lo, hi = boxes[owner]
        local = (point - data.xpos[owner]) @ data.xmat[owner].reshape(3, 3)
        return bool(np.all(local >= lo - COVER_MARGIN_M) and np.all(local <= hi + COVER_MARGIN_M))

    out: dict[int, _Part] = {}
    for owner, part in parts.items():
        children = [o for o, p in parts.items() if p.parent == owner]
        neighbours = [owner, part.parent, *children]
        covered = part.mass_kg <= FRAME_KG or any(inside(part.com, n) for n in neighbours)
        out[owner] = replace(part, covered=covered)
    return out


def _coverage(parts: dict[int, _Part]) -> float:
    total = sum(p.mass_kg for p in parts.values())
    covered = sum(p.mass_kg for p in parts.values() if p.covered)
    return covered / total if total > 0 else 0.0


def _servo_mass(robot: TeamRobotModel) -> float:
    total = 0.0
    for motor in robot.motors:
        found = find_servo(motor.servo) if motor.servo else None
        total += found.mass_kg if found is not None else 0.0
    return total


def _mass_split(robot: TeamRobotModel, model: mujoco.MjModel) -> dict[str, float]:
    """Mass per body part (the manifest's tags, a link's subtree taking its part; the rest is
    torso)."""
    tags = robot.manifest.parts
    split: dict[str, float] = {}
    for b in range(1, model.nbody):
        name = model.body(b).name
        if not (name == "r/torso" or name.startswith("r/link:")):
            continue
        part = "torso"
        walk = b
        while walk > 0:
            link = _link_name(model, walk)
            if link in tags and model.body(walk).name != "r/torso":
                part = tags[link]
                break
            walk = int(model.body_parentid[walk])
        split[part] = split.get(part, 0.0) + float(model.body_mass[b])
    return dict(sorted(split.items()))


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
    if m.servo_mass_kg > m.mass_kg * (1 + 1e-6):
        bad(
            "mass of the servos",
            f"the model weighs {m.mass_kg:.3f} kg, less than its servos alone "
            f"({m.servo_mass_kg:.3f} kg, the catalogue's mass of each motor's servo) (rule: "
            "the model weighs at least its servos)",
        )
    problems.extend(_physics_problems(robot, source))
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


def _physics_problems(robot: TeamRobotModel, source: str) -> list[ModelProblem]:
    """Dense parts, parts without collision shapes, and shapes touching across chains (see the
    module's rules)."""
    model = _standalone(robot)
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    out: list[ModelProblem] = []
    parts = _moving_parts(model, data)
    for part in parts.values():
        if part.shapes is not None and part.mass_kg > DENSE_PART_KG:
            extent = part.shapes[1] - part.shapes[0]
            density = part.mass_kg / float(np.prod(np.maximum(extent, 1e-3)))
            if density > PART_DENSITY_KG_M3:
                size = " x ".join(f"{v:.3f}" for v in extent)
                out.append(ModelProblem(
                    source=source, where=f"mass of {part.name}",
                    reason=f"{part.mass_kg:.4g} kg in the {size} m box around its shapes is "
                    f"{density:.0f} kg/m^3, above {PART_DENSITY_KG_M3:g} kg/m^3, solid "
                    "aluminium's (rule: mass per link plausible for its size)",
                ))  # fmt: skip
        if not part.covered:
            out.append(ModelProblem(
                source=source, where=f"collision shapes of {part.name}",
                reason=f"{part.mass_kg:.4g} kg whose centre of mass is outside the collision "
                "shapes of the link, its parent and its children (rule: every link that has "
                "mass has collision shapes that cover it)",
            ))  # fmt: skip
    out.extend(_touching_problems(robot, model, data, source))
    return out


def _touching_problems(
    robot: TeamRobotModel, model: mujoco.MjModel, data: mujoco.MjData, source: str
) -> list[ModelProblem]:
    """Pairs of links whose shapes overlap in a reference pose without the self-collision rule
    excluding them (in the match they would push each other apart from the start)."""
    excluded = {frozenset(pair) for pair in excluded_pairs(robot)}
    model.geom_margin[:] = NEAR_M
    joints = [model.joint(f"r/{name}") for name in robot.motor_names]
    found: dict[frozenset[str], str] = {}
    for label, pose in (("zero", [0.0] * len(joints)), ("standing", robot.standing_pose_rad)):
        for joint, value in zip(joints, pose, strict=True):
            data.qpos[joint.qposadr[0]] = value
        mujoco.mj_forward(model, data)
        for i, (g1, g2) in enumerate(data.contact.geom[: data.ncon].tolist()):
            a, b = int(model.geom_bodyid[g1]), int(model.geom_bodyid[g2])
            if a == b or model.body_weldid[a] == model.body_weldid[b]:
                continue
            if data.contact.dist[i] > -OVERLAP_M:
                continue  # near or touching: they collide in the match, as real parts do
            names = frozenset(model.body(x).name.removeprefix("r/") for x in (a, b))
            if names not in excluded and names not in found:
                found[names] = label
    out = []
    for names, label in found.items():
        first, second = sorted(n.removeprefix("link:") for n in names)
        out.append(ModelProblem(
            source=source, where=f"self-collision of {first} and {second}",
            reason=f"their collision shapes overlap in the {label} pose although the links are "
            "not joined through a joint of one chain (rule: self-collision is excluded only "
            "between a parent and its child, or links of one chain; shapes of different chains "
            "must not overlap)",
        ))  # fmt: skip
    return out
