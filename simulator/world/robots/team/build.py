"""Turns a team's model file and manifest into the MJCF the world places once per robot.

What is added to a URDF or MJCF file as teams write it: a free base at the root link, position
servos from the manifest, the IMU site and its sensors, the cameras, touch sensors for the foot
force sensors, bodies marking the hands and feet for the referee, and a team-coloured marker.
Collision geometry is simplified to one box per moving part, around the collision shapes of a
link and of every link welded to it (``collision: "link-boxes"``, the default: hundreds of small
shapes cost more than the rest of the world) or kept as it is; visual meshes are kept for
cameras and video. A foot's cleats are kept as the model's own shapes (:func:`_cleats`: the
Wolfgang's eight spheres), the rest of the foot, less the links carrying the cleats, becomes its
box; a foot without cleats stands on its box's four corners.

Names follow the world's contract (see :mod:`simulator.world.robots.humanoid`): the root body
``<prefix>/torso`` with the free joint ``<prefix>/root``, joints and actuators by HLVS motor name,
geoms ``<prefix>/<part>:<label>`` so the referee knows feet from hands, ``<prefix>/visual:...``
for what never collides. The template uses the placeholder :data:`PREFIX` for the prefix.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from xml.sax.saxutils import quoteattr

import mujoco
import numpy as np

from simulator.errors import ModelError, ModelProblem
from simulator.world.actuator import actuator_xml, line_constants
from simulator.world.robots.devices import imu_sensor, imu_site
from simulator.world.robots.team.devices import force_mjcf, imus_of
from simulator.world.robots.team.entries import Manifest
from simulator.world.robots.team.servos import motor_spec
from simulator.world.types import DeviceKind

PREFIX = "@ROBOT@"
HULL = (
    ("hands", 0, "hand_L"),
    ("hands", 1, "hand_R"),
    ("feet", 0, "foot_L"),
    ("feet", 1, "foot_R"),
)
MARKER_RADIUS_M = 0.04
# link-boxes: the model's own collision geoms are renamed to this prefix, made inert (no
# contact, no mass) and left out of the template's XML. Deleting them from the spec instead
# (``MjSpec.delete``, whose cost grows with the spec's size) took most of Wolfgang's load time:
# 293 geoms, about 15 s of CPU against 2.5 s now
DROPPED = "@DROPPED@"
CLEAT_BAND_M = 0.003
"""A cleat's lowest point is at most this far above the foot's lowest point (standing pose)."""
CLEAT_MAX_M = 0.03
"""A cleat is a primitive shape at most this wide (cleats are small; a sole plate is not)."""
_PRIMITIVES = frozenset(
    int(t)
    for t in (
        mujoco.mjtGeom.mjGEOM_SPHERE,
        mujoco.mjtGeom.mjGEOM_CAPSULE,
        mujoco.mjtGeom.mjGEOM_CYLINDER,
        mujoco.mjtGeom.mjGEOM_ELLIPSOID,
        mujoco.mjtGeom.mjGEOM_BOX,
    )
)


@dataclass(frozen=True, slots=True)
class Template:
    """The robot's MJCF with :data:`PREFIX` in every name, ready to be instantiated."""

    key: str  # prefix of this model's mesh asset names (shared by its robots)
    assets: str
    body: ET.Element
    actuators: str
    sensors: str
    standing_height_m: float  # root body origin above the ground at the zero pose
    root_body: str  # the link that became <prefix>/torso
    ranges: dict[str, tuple[float, float]]  # motor name -> joint range (rad)
    trunk_body: str  # the heaviest body (template name): its visuals wear the team colour


def _problem(manifest: Manifest, where: str, reason: str) -> ModelProblem:
    return ModelProblem(source=str(manifest.path), where=where, reason=reason)


def _bodies(spec: mujoco.MjSpec) -> list[mujoco.MjsBody]:
    out: list[mujoco.MjsBody] = []

    def walk(body: mujoco.MjsBody) -> None:
        for child in body.bodies:
            out.append(child)
            walk(child)

    walk(spec.worldbody)
    return out


def _is_collision(geom: mujoco.MjsGeom) -> bool:
    return bool(geom.contype or geom.conaffinity)


def _owner(model: mujoco.MjModel, body: int) -> int:
    """The body itself if it moves (has a joint or hangs from the world), else the nearest
    ancestor it is welded to."""
    while model.body_jntnum[body] == 0 and model.body_parentid[body] != 0:
        body = int(model.body_parentid[body])
    return body


def _cleats(model: mujoco.MjModel, manifest: Manifest) -> set[int]:
    """Geom ids of the feet's cleats: in each foot (the manifest's foot link and every link
    welded to it), the small primitive collision shapes (at most :data:`CLEAT_MAX_M` across)
    whose lowest point in the standing pose is within :data:`CLEAT_BAND_M` of the foot's lowest
    point, when there are at least three of them (a foot resting on fewer is not on cleats)."""
    data = mujoco.MjData(model)
    joints = {m.name: m.joint for m in manifest.motors}
    for name, rad in manifest.standing_pose_rad.items():
        data.qpos[model.jnt_qposadr[model.joint(joints[name]).id]] = rad
    mujoco.mj_kinematics(model, data)
    out: set[int] = set()
    for link in manifest.feet:
        owner = _owner(model, model.body(link).id)
        bottoms: dict[int, float] = {}
        for g in range(model.ngeom):
            if not (model.geom_contype[g] or model.geom_conaffinity[g]):
                continue
            if _owner(model, int(model.geom_bodyid[g])) != owner:
                continue
            rot = data.geom_xmat[g].reshape(3, 3)
            centre = data.geom_xpos[g] + rot @ model.geom_aabb[g][:3]
            bottoms[g] = float(centre[2] - np.abs(rot[2]) @ model.geom_aabb[g][3:])
        if not bottoms:
            continue
        lowest = min(bottoms.values())
        cleats = {
            g
            for g, bottom in bottoms.items()
            if bottom <= lowest + CLEAT_BAND_M
            and int(model.geom_type[g]) in _PRIMITIVES
            and 2 * float(model.geom_aabb[g][3:].max()) <= CLEAT_MAX_M
        }
        if len(cleats) >= 3:
            out |= cleats
    return out


def _cleat_links(model: mujoco.MjModel, cleats: set[int]) -> set[int]:
    """The cleats and the other shapes of the links that carry them (a cleat link's stem above
    its tip): left out of the foot's box, which keeps its sole plate above the grass."""
    out = set(cleats)
    for g in cleats:
        body = int(model.geom_bodyid[g])
        if _owner(model, body) != body:  # a cleat link welded to the foot, not the foot itself
            out |= {h for h in range(model.ngeom) if int(model.geom_bodyid[h]) == body}
    return out


def _collision_boxes(
    model: mujoco.MjModel, *, merge_welded: bool, skip: set[int] | None = None
) -> dict[int, tuple[np.ndarray, np.ndarray]]:
    """Body id -> (min, max) corners, in that body's frame, of its collision geoms, at the zero
    pose. With ``merge_welded`` a body also takes the geoms of every body welded to it (no joint
    between them): one box per moving part. The feet's cleats, sole plates and frames become one
    box per foot: a few contacts with the turf where dozens of small shapes made hundreds.
    Geoms in ``skip`` (the cleats, kept as they are) are left out."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    boxes: dict[int, tuple[np.ndarray, np.ndarray]] = {}
    for g in range(model.ngeom):
        if not (model.geom_contype[g] or model.geom_conaffinity[g]) or g in (skip or ()):
            continue
        body = int(model.geom_bodyid[g])
        owner = _owner(model, body) if merge_welded else body
        centre, half = model.geom_aabb[g][:3], model.geom_aabb[g][3:]
        rot = data.geom_xmat[g].reshape(3, 3)
        world = data.geom_xpos[g] + (centre + signs * half) @ rot.T
        local = (world - data.xpos[owner]) @ data.xmat[owner].reshape(3, 3)
        lo, hi = local.min(axis=0), local.max(axis=0)
        if owner in boxes:
            lo, hi = np.minimum(lo, boxes[owner][0]), np.maximum(hi, boxes[owner][1])
        boxes[owner] = (lo, hi)
    return boxes


def _add_cleat(
    body: mujoco.MjsBody, model: mujoco.MjModel, geom: int, owner: int, name: str
) -> None:
    """Copy cleat ``geom`` onto its moving part ``owner`` (the body in the spec), where the
    part's force sensor sites see its contacts (a touch sensor counts its own body's)."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    rot = data.xmat[owner].reshape(3, 3)
    local = rot.T @ data.geom_xmat[geom].reshape(3, 3)
    quat = np.zeros(4)
    mujoco.mju_mat2Quat(quat, local.flatten())
    cleat = body.add_geom()
    cleat.name = name
    cleat.type = mujoco.mjtGeom(int(model.geom_type[geom]))
    cleat.size = model.geom_size[geom]
    cleat.pos = rot.T @ (data.geom_xpos[geom] - data.xpos[owner])
    cleat.quat = quat
    cleat.group = 3
    cleat.mass = 0
    cleat.rgba = (0.5, 0.5, 0.5, 0.0)


def _sensor_sites(
    model: mujoco.MjModel,
    manifest: Manifest,
    owner_boxes: dict[int, tuple[np.ndarray, np.ndarray]],
) -> dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]:
    """Owner link -> sensor link -> (min, max) of its touch sensor site in the owner's frame.

    The turf touches a foot at its cleats or its box's bottom corners, so each force sensor
    measures the quarter of the sole (split at the centre of the box around the whole foot,
    cleats included) its link lies in, from 15 mm below to 5 mm above the sole (the soft turf
    lets a loaded foot sink about 7 mm, see :mod:`simulator.world.field`)."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    out: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]] = {}
    for link in manifest.force_sensors.values():
        body = model.body(link).id
        owner = _owner(model, body)
        if owner not in owner_boxes:
            continue
        lo, hi = owner_boxes[owner]
        centre = (data.xpos[body] - data.xpos[owner]) @ data.xmat[owner].reshape(3, 3)
        mid = (lo + hi) / 2
        site_lo = np.where(centre < mid, lo - 2e-3, mid)
        site_hi = np.where(centre < mid, mid, hi + 2e-3)
        site_lo[2], site_hi[2] = lo[2] - 15e-3, lo[2] + 5e-3
        out.setdefault(model.body(owner).name, {})[link] = (site_lo, site_hi)
    return out


def _parts(spec: mujoco.MjSpec, manifest: Manifest) -> dict[str, str]:
    """Link -> body part; a link's part is the manifest's, else its parent's, else torso."""
    out: dict[str, str] = {}

    def walk(body: mujoco.MjsBody, inherited: str) -> None:
        for child in body.bodies:
            part = manifest.parts.get(child.name, inherited)
            out[child.name] = part
            walk(child, part)

    walk(spec.worldbody, "torso")
    return out


def _validate(spec: mujoco.MjSpec, manifest: Manifest) -> list[ModelProblem]:
    """Every problem of the model file against its manifest, in the order a reader fixes them:
    the tree, the motors' joints, joints no motor drives, the servos' lines, the named links."""
    joints = {j.name: j for b in _bodies(spec) for j in b.joints}
    return [
        *_tree_problems(spec, manifest, joints),
        *_motor_joint_problems(manifest, joints),
        *_joint_problems(spec, manifest, joints),
        *_line_problems(manifest),
        *_link_problems(spec, manifest),
    ]


def _tree_problems(
    spec: mujoco.MjSpec, manifest: Manifest, joints: dict[str, mujoco.MjsJoint]
) -> list[ModelProblem]:
    """One tree of links, with something to move."""
    problems = []
    if len(spec.worldbody.bodies) != 1:
        problems.append(
            _problem(
                manifest,
                "model_file",
                f"{len(spec.worldbody.bodies)} root links; expected one tree",
            )
        )
    if not joints:
        problems.append(
            _problem(
                manifest, "model_file", "the model has no movable joints (a robot needs motors)"
            )
        )
    return problems


def _motor_joint_problems(
    manifest: Manifest, joints: dict[str, mujoco.MjsJoint]
) -> list[ModelProblem]:
    """Each motor's joint: there, revolute, and its manifest range within the file's."""
    problems = []
    for i, motor in enumerate(manifest.motors):
        joint = joints.get(motor.joint)
        if joint is None:
            hint = _did_you_mean(motor.joint, joints)
            problems.append(
                _problem(
                    manifest, f"/motors/{i}/joint", f"no joint {motor.joint!r} in the model{hint}"
                )
            )
        elif joint.type not in (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE):
            problems.append(
                _problem(
                    manifest, f"/motors/{i}/joint", f"joint {motor.joint!r} is not a revolute joint"
                )
            )
        elif motor.range_rad is not None and joint.limited and joint.range[0] < joint.range[1]:
            lo, hi = float(joint.range[0]), float(joint.range[1])
            if motor.range_rad[0] < lo - 1e-9 or motor.range_rad[1] > hi + 1e-9:
                problems.append(
                    _problem(
                        manifest,
                        f"/motors/{i}/range_rad",
                        f"[{motor.range_rad[0]:g}, {motor.range_rad[1]:g}] rad is wider than "
                        f"the model file's range [{lo:g}, {hi:g}] of joint {motor.joint!r} (the "
                        "manifest may narrow a joint's range, never widen it)",
                    )
                )
    return problems


def _joint_problems(
    spec: mujoco.MjSpec, manifest: Manifest, joints: dict[str, mujoco.MjsJoint]
) -> list[ModelProblem]:
    """Free joints below the root, and movable joints no motor drives."""
    problems = []
    roots = list(spec.worldbody.bodies)
    for body in _bodies(spec):
        for joint in body.joints:
            if joint.type == mujoco.mjtJoint.mjJNT_FREE and body not in roots:
                problems.append(
                    _problem(
                        manifest,
                        "model_file",
                        f"link {body.name!r} has a free joint but is not the root link: a robot "
                        "is one tree of joints (only its root may float)",
                    )
                )
    motor_joints = {m.joint for m in manifest.motors}
    for name, joint in joints.items():
        if name not in motor_joints and joint.type != mujoco.mjtJoint.mjJNT_FREE:
            problems.append(
                _problem(
                    manifest,
                    "/motors",
                    f"joint {name!r} is movable but not a motor; list it under "
                    "motors (unactuated joints are not allowed)",
                )
            )
    return problems


def _link_problems(spec: mujoco.MjSpec, manifest: Manifest) -> list[ModelProblem]:
    """Every link the manifest names (IMUs, cameras, force sensors, jersey, parts, hands, feet)."""
    links = {b.name for b in _bodies(spec)}
    named: list[tuple[str, str]] = [(f"{i.where}/link", i.link) for i in imus_of(manifest)]
    named += [(f"/cameras/{i}/link", c.link) for i, c in enumerate(manifest.cameras)]
    named += [(f"/force_sensors/{k}", v) for k, v in manifest.force_sensors.items()]
    named += [("/jersey/link", manifest.jersey.link)] if manifest.jersey is not None else []
    named += [(f"/parts ({part})", link) for link, part in manifest.parts.items()]
    named += [
        ("/hands/left", manifest.hands[0]),
        ("/hands/right", manifest.hands[1]),
        ("/feet/left", manifest.feet[0]),
        ("/feet/right", manifest.feet[1]),
    ]
    return [
        _problem(manifest, where, f"no link {link!r} in the model{_did_you_mean(link, links)}")
        for where, link in named
        if link not in links
    ]


def _line_problems(manifest: Manifest) -> list[ModelProblem]:
    """Friction and damping that leave a servo no torque before its no-load speed (the
    manifest's ``joint_damping`` / ``joint_frictionloss`` replacing the catalogue's)."""
    failing = []
    for motor in manifest.motors:
        spec = motor_spec(motor, manifest)
        try:
            line_constants(spec)
        except ValueError:
            room = (spec.max_torque_nm - spec.static_friction_nm) / spec.max_velocity_rad_s
            failing.append(f"{motor.name} (at most {max(room, 0.0):.3g} N m s/rad)")
    if not failing:
        return []
    where = "/joint_damping" if manifest.joint_damping is not None else "/joint_frictionloss"
    if manifest.joint_damping is None and manifest.joint_frictionloss is None:
        where = "/motors"
    return [
        _problem(
            manifest,
            where,
            "friction and damping would take a servo's whole stall torque before it reaches its "
            f"no-load speed: {', '.join(failing)}; lower joint_damping / joint_frictionloss "
            "or leave them out to take the catalogue servos' own",
        )
    ]


def _did_you_mean(name: str, known: object) -> str:
    import difflib

    close = difflib.get_close_matches(name, list(known), n=1)  # type: ignore[call-overload]
    return f"; did you mean {close[0]!r}?" if close else ""


@dataclass(frozen=True, slots=True)
class _Shapes:
    """What the edits read of the model file as it was compiled before them (zero pose)."""

    original: mujoco.MjModel
    boxes: dict[int, tuple[np.ndarray, np.ndarray]]  # body id -> its own collision box
    owner_boxes: dict[int, tuple[np.ndarray, np.ndarray]]  # moving part -> its link box
    sensor_sites: dict[str, dict[str, tuple[np.ndarray, np.ndarray]]]  # see _sensor_sites
    cleats: set[int]  # geom ids kept as the feet's own shapes

    @classmethod
    def of(cls, original: mujoco.MjModel, manifest: Manifest) -> _Shapes:
        cleats = _cleats(original, manifest) if manifest.collision == "link-boxes" else set()
        return cls(
            original=original,
            boxes=_collision_boxes(original, merge_welded=False),
            sensor_sites=_sensor_sites(
                original, manifest, _collision_boxes(original, merge_welded=True)
            ),
            owner_boxes=_collision_boxes(
                original, merge_welded=True, skip=_cleat_links(original, cleats)
            ),
            cleats=cleats,
        )


def build_template(spec: mujoco.MjSpec, manifest: Manifest, *, key: str) -> Template:
    """Edit ``spec`` (consumed) into the world's robot template. Raises :class:`ModelError`.

    The steps, in order: validate, measure the file's shapes (:class:`_Shapes`), name the
    shared assets by ``key``, edit each link (:func:`_edit_body`), replace the file's base by
    the world's free joint and add the team marker, drop the file's actuators and sensors (the
    world writes its own), then measure the standing height and write the template."""
    problems = _validate(spec, manifest)
    if problems:
        raise ModelError(problems)
    shapes = _Shapes.of(spec.compile(), manifest)
    parts = _parts(spec, manifest)
    root = spec.worldbody.bodies[0]
    root_name = root.name
    ranges: dict[str, tuple[float, float]] = {}
    _name_assets(spec, key)
    for body in [root, *_bodies(spec)[1:]]:
        ranges |= _edit_body(spec, body, shapes, manifest, part=parts[body.name], key=key)
        body.name = f"{PREFIX}/torso" if body is root else f"{PREFIX}/link:{body.name}"
    _add_base_and_marker(spec, root, shapes.original, manifest, root_name=root_name)
    for actuator in list(spec.actuators):
        spec.delete(actuator)
    for sensor in list(spec.sensors):
        spec.delete(sensor)
    standing = _standing_height(spec, manifest.standing_pose_rad)
    xml = spec.to_xml()
    trunk = shapes.original.body(int(np.argmax(shapes.original.body_mass))).name
    trunk_name = f"{PREFIX}/torso" if trunk == root_name else f"{PREFIX}/link:{trunk}"
    return _template(
        xml,
        manifest,
        key=key,
        standing=standing,
        root_name=root_name,
        ranges=ranges,
        trunk=trunk_name,
    )


def _name_assets(spec: mujoco.MjSpec, key: str) -> None:
    """Meshes, textures and materials are shared by the model's robots: named by the key, so
    that two models that both have a "black" material can play each other."""
    for mesh in spec.meshes:
        mesh.name = f"{key}:{mesh.name}"
    for texture in spec.textures:
        if texture.name:
            texture.name = f"{key}:{texture.name}"
    for material in spec.materials:
        material.name = f"{key}:{material.name}"
        material.textures = [f"{key}:{t}" if t else t for t in material.textures]


def _edit_body(
    spec: mujoco.MjSpec,
    body: mujoco.MjsBody,
    shapes: _Shapes,
    manifest: Manifest,
    *,
    part: str,
    key: str,
) -> dict[str, tuple[float, float]]:
    """One link made the world's: its inertia fixed, its geoms renamed (or dropped for its
    box), its collision box and cleats, its joints made servos, then the devices and markers
    the manifest puts on it. Returns the ranges (rad) of its motors by motor name."""
    b = shapes.original.body(body.name).id
    _fix_inertia(body, shapes.original, b)
    _name_geoms(body, manifest, part=part, key=key)
    # the file's own sites and cameras: the world's are the manifest's (/imu, /cameras), and
    # their names, not the robot's, would repeat in a world of several robots
    for own in [*body.sites, *body.cameras]:
        spec.delete(own)
    _add_collision(body, shapes, manifest, b, part=part)
    ranges = _make_servos(body, manifest)
    _add_sensor_sites(body, shapes, manifest, b)
    _add_hulls_and_cameras(body, shapes, manifest, b)
    return ranges


def _fix_inertia(body: mujoco.MjsBody, original: mujoco.MjModel, b: int) -> None:
    """The compiled inertia written explicitly (the geoms lose their mass), kept above zero."""
    body.explicitinertial = True
    body.mass = max(float(original.body_mass[b]), 1e-6)
    body.ipos = original.body_ipos[b]
    body.iquat = original.body_iquat[b]
    body.inertia = np.maximum(original.body_inertia[b], 1e-9)
    body.fullinertia = np.full(6, np.nan)


def _name_geoms(body: mujoco.MjsBody, manifest: Manifest, *, part: str, key: str) -> None:
    """Collision geoms named by body part (dropped under ``link-boxes``), the rest visuals;
    massless, their meshes and materials by the model's key."""
    link = body.name
    visuals = 0
    for i, geom in enumerate(list(body.geoms)):
        if _is_collision(geom):
            if manifest.collision == "link-boxes":
                _drop(geom, f"{link}_{i}")
                continue
            geom.name = f"{PREFIX}/{part}:{link}_{i}"
        else:
            geom.name = f"{PREFIX}/visual:{link}_{visuals}"
            visuals += 1
        geom.mass = 0
        geom.density = 0
        if geom.type == mujoco.mjtGeom.mjGEOM_MESH:
            geom.meshname = f"{key}:{geom.meshname}"
        if geom.material:
            geom.material = f"{key}:{geom.material}"


def _add_collision(
    body: mujoco.MjsBody, shapes: _Shapes, manifest: Manifest, b: int, *, part: str
) -> None:
    """Under ``link-boxes``: the moving part's box, then the cleats it carries."""
    link = body.name
    if manifest.collision == "link-boxes" and b in shapes.owner_boxes:
        lo, hi = shapes.owner_boxes[b]
        box = body.add_geom()
        box.name = f"{PREFIX}/{part}:{link}"
        box.type = mujoco.mjtGeom.mjGEOM_BOX
        box.pos = (lo + hi) / 2
        box.size = np.maximum((hi - lo) / 2, 1e-3)
        box.group = 3
        box.mass = 0
        box.rgba = (0.5, 0.5, 0.5, 0.0)
    original = shapes.original
    own = [g for g in sorted(shapes.cleats) if _owner(original, int(original.geom_bodyid[g])) == b]
    for k, g in enumerate(own):
        _add_cleat(body, original, g, b, f"{PREFIX}/{part}:{link}_cleat_{k}")


def _make_servos(body: mujoco.MjsBody, manifest: Manifest) -> dict[str, tuple[float, float]]:
    """The link's joints named by motor, narrowed to the manifest's range and given the servo's
    damping, friction and armature; the file's own free base is left (replaced later)."""
    motors = {m.joint: m for m in manifest.motors}
    ranges: dict[str, tuple[float, float]] = {}
    for joint in body.joints:
        if joint.type == mujoco.mjtJoint.mjJNT_FREE:
            continue
        motor = motors[joint.name]
        if motor.range_rad is not None:
            joint.range = motor.range_rad
            joint.limited = mujoco.mjtLimited.mjLIMITED_TRUE
        ranges[motor.name] = (float(joint.range[0]), float(joint.range[1]))
        joint.name = f"{PREFIX}/{motor.name}"
        physics = motor_spec(motor, manifest)
        joint.damping = [physics.damping_nm_s_per_rad, 0.0, 0.0]
        joint.frictionloss = physics.static_friction_nm
        joint.armature = physics.armature_kg_m2
    return ranges


def _add_sensor_sites(body: mujoco.MjsBody, shapes: _Shapes, manifest: Manifest, b: int) -> None:
    """The IMU sites and the force sensors' touch sites on this link."""
    link = body.name
    for k, imu in enumerate(imus_of(manifest)):
        if imu.link == link:
            body.add_site().name = f"{PREFIX}/{imu_site(k)}"
    for sensor, sensor_link in manifest.force_sensors.items():
        if manifest.collision == "link-boxes" and sensor_link in shapes.sensor_sites.get(link, {}):
            lo, hi = shapes.sensor_sites[link][sensor_link]
        elif sensor_link == link and manifest.collision != "link-boxes":
            lo, hi = shapes.boxes.get(b, (np.full(3, -0.01), np.full(3, 0.01)))
            lo, hi = lo - 2e-3, hi + 2e-3
        else:
            continue
        site = body.add_site()
        site.name = f"{PREFIX}/site:{force_mjcf(sensor)}"
        site.type = mujoco.mjtGeom.mjGEOM_BOX
        site.pos = (lo + hi) / 2
        site.size = (hi - lo) / 2
        site.group = 4


def _add_hulls_and_cameras(
    body: mujoco.MjsBody, shapes: _Shapes, manifest: Manifest, b: int
) -> None:
    """The bodies marking hands and feet for the referee, and the manifest's cameras (looking
    along the link's x axis, the vertical field of view from the horizontal one)."""
    link = body.name
    for group, side, hull in HULL:
        if getattr(manifest, group)[side] == link:
            marker = body.add_body()
            marker.name = f"{PREFIX}/{hull}"
            lo, hi = shapes.boxes.get(b, (np.zeros(3), np.zeros(3)))
            marker.pos = (lo + hi) / 2
    for camera in manifest.cameras:
        if camera.link == link:
            cam = body.add_camera()
            cam.name = f"{PREFIX}/{camera.name}"
            cam.pos = camera.pos_m
            cam.alt.type = mujoco.mjtOrientation.mjORIENTATION_XYAXES
            cam.alt.xyaxes = (0, -1, 0, 0, 0, 1)
            cam.fovy = math.degrees(
                2 * math.atan(math.tan(camera.fov_rad / 2) * camera.height / camera.width)
            )


def _add_base_and_marker(
    spec: mujoco.MjSpec,
    root: mujoco.MjsBody,
    original: mujoco.MjModel,
    manifest: Manifest,
    *,
    root_name: str,
) -> None:
    """The world's free joint in place of the root's own joints, and the team-coloured marker
    on top of the link holding the robot's highest point."""
    for joint in root.joints:
        spec.delete(joint)
    root.add_freejoint().name = f"{PREFIX}/root"
    top = _top_of(original, manifest)
    head = root if top[0] == root_name else spec.body(f"{PREFIX}/link:{top[0]}")
    marker = head.add_geom()
    marker.name = f"{PREFIX}/visual:marker"
    marker.type = mujoco.mjtGeom.mjGEOM_CYLINDER
    marker.size = (MARKER_RADIUS_M, 0.006, 0)
    marker.pos = top[1]
    marker.contype = marker.conaffinity = 0
    marker.group = 1
    marker.mass = 0


def _top_of(model: mujoco.MjModel, manifest: Manifest) -> tuple[str, np.ndarray]:
    """The link holding the robot's highest point at the zero pose, and that point (link frame)."""
    data = mujoco.MjData(model)
    mujoco.mj_kinematics(model, data)
    best = (-math.inf, 0, np.zeros(3))
    for g in range(model.ngeom):
        centre, half = model.geom_aabb[g][:3], model.geom_aabb[g][3:]
        z = data.geom_xpos[g][2] + float(np.abs(data.geom_xmat[g].reshape(3, 3)[2]) @ half)
        if z > best[0]:
            b = int(model.geom_bodyid[g])
            top_world = data.geom_xpos[g] + data.geom_xmat[g].reshape(3, 3) @ centre
            top_world = top_world.copy()
            top_world[2] = z + 0.006
            local = data.xmat[b].reshape(3, 3).T @ (top_world - data.xpos[b])
            best = (z, b, local)
    return model.body(best[1]).name, best[2]


def _drop(geom: mujoco.MjsGeom, name: str) -> None:
    """Leave ``geom`` out of the template (see ``DROPPED``); inert until then: a small sphere
    without contacts or mass (its mesh, if any, may be renamed meanwhile)."""
    geom.name = f"{DROPPED}{name}"
    geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
    geom.size = (0.001, 0.0, 0.0)
    geom.fromto = np.full(6, np.nan)  # unset: a sphere takes no fromto
    geom.meshname = ""
    geom.contype = geom.conaffinity = 0
    geom.mass = 0
    geom.density = 0


def _standing_height(spec: mujoco.MjSpec, pose: dict[str, float]) -> float:
    """Height of the root above the ground when the lowest collision geom touches it, the
    joints in the standing pose."""
    model = spec.compile()
    data = mujoco.MjData(model)
    for name, rad in pose.items():
        data.qpos[model.jnt_qposadr[model.joint(f"{PREFIX}/{name}").id]] = rad
    mujoco.mj_kinematics(model, data)
    lowest = math.inf
    for g in range(model.ngeom):
        if not (model.geom_contype[g] or model.geom_conaffinity[g]):
            continue
        half = model.geom_aabb[g][3:]
        centre = data.geom_xpos[g] + data.geom_xmat[g].reshape(3, 3) @ model.geom_aabb[g][:3]
        extent = float(np.abs(data.geom_xmat[g].reshape(3, 3)[2]) @ half)
        lowest = min(lowest, centre[2] - extent)
    root_z = float(data.xpos[1][2])
    return root_z - lowest


def _expand_defaults(doc: ET.Element) -> None:
    """Write every attribute an element takes from its default class (``class``, an ancestor's
    ``childclass``, else ``main``) onto the element itself: the template leaves the classes out
    (the world has its own), and MJCF files such as the MuJoCo Menagerie's set mesh scales,
    collision flags and geom types there."""
    classes: dict[str, dict[str, dict[str, str]]] = {}

    def collect(node: ET.Element, inherited: dict[str, dict[str, str]]) -> None:
        name = node.get("class", "main")
        own = {tag: dict(attrs) for tag, attrs in inherited.items()}
        for child in node:
            if child.tag != "default":
                own[child.tag] = {**own.get(child.tag, {}), **child.attrib}
        classes[name] = own
        for child in node:
            if child.tag == "default":
                collect(child, own)

    for top in doc.findall("default"):
        collect(top, {})
        doc.remove(top)
    if not classes:
        return

    def fill(element: ET.Element, active: str) -> None:
        for child in element:
            own = child.get("class", active)
            values = classes.get(own, classes.get("main", {})).get(child.tag, {})
            for key, value in values.items():
                if key not in child.attrib and not _conflicts(child, key):
                    child.set(key, value)
            fill(child, child.get("childclass", active) if child.tag == "body" else active)

    for section in doc:
        fill(section, "main")


def _conflicts(element: ET.Element, key: str) -> bool:
    """A default attribute the element's own attributes replace (MJCF: ``fromto`` sets a
    geom's position and length; an orientation is given in one of several forms)."""
    orientations = {"quat", "euler", "axisangle", "xyaxes", "zaxis"}
    if key in orientations:
        return bool(orientations & set(element.attrib))
    if key in ("pos", "size") and "fromto" in element.attrib and element.tag == "geom":
        return key == "pos"
    return False


def _template(
    xml: str,
    manifest: Manifest,
    *,
    key: str,
    standing: float,
    root_name: str,
    ranges: dict[str, tuple[float, float]],
    trunk: str,
) -> Template:
    doc = ET.fromstring(xml)
    _expand_defaults(doc)
    asset = doc.find("asset")
    assets = "".join(
        ET.tostring(e, encoding="unicode") for e in (asset if asset is not None else [])
    )
    worldbody = doc.find("worldbody")
    assert worldbody is not None
    body = worldbody.find("body")
    assert body is not None
    for parent in list(body.iter()):
        for child in [c for c in parent if c.get("name", "").startswith(DROPPED)]:
            parent.remove(child)
    for element in body.iter():
        element.attrib.pop("class", None)
        element.attrib.pop("childclass", None)
    motors = "".join(
        actuator_xml(f"{PREFIX}/{m.name}", f"{PREFIX}/{m.name}", motor_spec(m, manifest))
        for m in manifest.motors
    )
    sensors = "".join(
        f'<accelerometer name="{PREFIX}/{imu_sensor(k, DeviceKind.ACCELEROMETER)}" '
        f'site="{PREFIX}/{imu_site(k)}"/>'
        f'<gyro name="{PREFIX}/{imu_sensor(k, DeviceKind.GYRO)}" site="{PREFIX}/{imu_site(k)}"/>'
        for k in range(len(imus_of(manifest)))
    ) + (
        f'<subtreelinvel name="{PREFIX}/com_velocity" body="{PREFIX}/torso"/>'
        + "".join(
            f"<touch name={quoteattr(f'{PREFIX}/{force_mjcf(n)}')} "
            f"site={quoteattr(f'{PREFIX}/site:{force_mjcf(n)}')}/>"
            for n in manifest.force_sensors
        )
    )
    return Template(
        key=key,
        assets=assets,
        body=body,
        actuators=motors,
        sensors=sensors,
        standing_height_m=standing,
        root_body=root_name,
        ranges=ranges,
        trunk_body=trunk,
    )
