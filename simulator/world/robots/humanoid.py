"""Our humanoid: the built-in robot model (:class:`RobotModel`) and its MJCF (primitive geoms
only), parameterised by :class:`HumanoidGeometry`.

Each sole stands on four spherical cleats, one in each corner (``foot:cleat_<side><l|r><b|f>``),
under a plate (``foot:sole_<side>``) two cleat radii above the ground: four contact points per
foot on the soft turf (:mod:`simulator.world.field`), each under its corner's force sensor.

Geom names carry their body part for contact reporting: ``<prefix>/<part>:<label>`` where part is
a :class:`referee.snapshot.BodyPart` value (foot, hand, arm, head, torso, leg). Visual-only geoms
(markers) use the part ``visual`` and never collide.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from robot import HumanoidGeometry
from simulator.world.actuator import actuator_xml, joint_attributes
from simulator.world.robots.devices import DeviceNames
from simulator.world.robots.model import (
    FORCE_SENSORS,
    CameraSpec,
    MotorLookup,
    MotorSpec,
    RobotMjcf,
)

LIMB_RGBA = "0.3 0.3 0.33 1"
FOOT_RGBA = "0.12 0.12 0.12 1"
HEAD_RGBA = "0.85 0.85 0.85 1"


def _f(*values: float) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _inertial(mass: float, radius: float) -> str:
    i = 0.4 * mass * radius * radius
    return f'<inertial pos="0 0 0" mass="{mass:.6g}" diaginertia="{_f(i, i, i)}"/>'


class _Writer:
    def __init__(self, model: RobotModel, prefix: str, contype: int, conaffinity: int) -> None:
        self.model = model
        self.p = prefix
        self.col = f'contype="{contype}" conaffinity="{conaffinity}"'

    def joint(self, motor: str, axis: tuple[float, float, float]) -> str:
        spec = self.model.motor(motor)
        return (
            f'<joint name="{self.p}/{motor}" type="hinge" axis="{_f(*axis)}" '
            f'range="{_f(spec.lower_rad, spec.upper_rad)}" {joint_attributes(spec)} '
            f'armature="{self.model.joint_armature}"/>'
        )

    def geom(self, part: str, label: str, attrs: str, rgba: str, mass: float) -> str:
        return (
            f'<geom name="{self.p}/{part}:{label}" {attrs} rgba="{rgba}" mass="{mass:.6g}" '
            f"{self.col}/>"
        )

    def visual(self, label: str, attrs: str, rgba: str) -> str:
        return (
            f'<geom name="{self.p}/visual:{label}" {attrs} rgba="{rgba}" mass="0" '
            f'contype="0" conaffinity="0" group="1"/>'
        )


def _leg(w: _Writer, side: str) -> str:
    g = w.model.geometry
    sign = 1.0 if side == "L" else -1.0
    small = _inertial(g.joint_link_kg, g.foot_half_width_m / 2)
    r_thigh = g.foot_half_width_m * 0.65
    thigh_shape = (
        f'type="capsule" fromto="{_f(0, 0, -r_thigh, 0, 0, -g.thigh_m)}" size="{r_thigh:.6g}"'
    )
    shank_shape = (
        f'type="capsule" fromto="{_f(0, 0, 0, 0, 0, -g.shank_m)}" size="{r_thigh * 0.9:.6g}"'
    )
    if w.model.leg_box_m is not None:
        depth, width, forward, above_knee = w.model.leg_box_m
        thigh_shape, shank_shape = (
            f'type="box" pos="{_f(forward, 0, top - length / 2)}" '
            f'size="{_f(depth, width, length / 2)}"'
            for top, length in ((0.0, g.thigh_m), (above_knee, g.shank_m + above_knee))
        )
    thigh = w.geom("leg", "thigh_" + side, thigh_shape, LIMB_RGBA, g.thigh_kg)
    shank = w.geom("leg", "shank_" + side, shank_shape, LIMB_RGBA, g.shank_kg)
    return f"""
<body name="{w.p}/hip_yaw_{side}" pos="{_f(0, sign * g.hip_y_m, g.hip_z_m)}">
 {small}{w.joint("PelvY" + side, (0, 0, 1))}
 <body name="{w.p}/hip_roll_{side}">
  {small}{w.joint("Pelv" + side, (1, 0, 0))}
  <body name="{w.p}/thigh_{side}">
   {w.joint("LegUpper" + side, (0, -1, 0))}
   {thigh}
   <body name="{w.p}/shank_{side}" pos="{_f(0, 0, -g.thigh_m)}">
    {w.joint("LegLower" + side, (0, 1, 0))}
    {shank}
    <body name="{w.p}/ankle_{side}" pos="{_f(0, 0, -g.shank_m)}">
     {small}{w.joint("Ankle" + side, (0, -1, 0))}
     <body name="{w.p}/foot_{side}">
      {w.joint("Foot" + side, (1, 0, 0))}
      {_foot(w, side)}
      {_foot_sites(w, side)}
     </body>
    </body>
   </body>
  </body>
 </body>
</body>"""


def _foot(w: _Writer, side: str) -> str:
    """The foot's geoms: the sole plate resting on four cleats at its corners, and the league's
    test robot's ankle box above it."""
    g = w.model.geometry
    hl, hw, ht = g.foot_half_length_m, g.foot_half_width_m, g.foot_half_thickness_m
    fx, sole = g.foot_forward_m, -g.ankle_height_m
    cleat = g.cleat_radius_m
    plate = ht - cleat  # half thickness of the plate resting on the cleats
    foot = w.geom(
        "foot",
        "sole_" + side,
        f'type="box" pos="{_f(fx, 0, sole + 2 * cleat + plate)}" size="{_f(hl, hw, plate)}"',
        FOOT_RGBA,
        g.foot_kg,
    )
    if w.model.ankle_box_m is not None:
        bx, bz, bhl, bhw, bhh = w.model.ankle_box_m
        foot += w.geom(
            "foot",
            "ankle_" + side,
            f'type="box" pos="{_f(bx, 0, bz)}" size="{_f(bhl, bhw, bhh)}"',
            FOOT_RGBA,
            0.0,
        )
    for ny, y_name in ((1.0, "l"), (-1.0, "r")):
        for nx, x_name in ((-1.0, "b"), (1.0, "f")):
            at = _f(fx + nx * (hl - cleat), ny * (hw - cleat), sole + cleat)
            foot += w.geom(
                "foot",
                f"cleat_{side}{y_name}{x_name}",
                f'type="sphere" pos="{at}" size="{cleat:.6g}"',
                FOOT_RGBA,
                0.0,
            )
    return foot


def _foot_sites(w: _Writer, side: str) -> str:
    """The foot's four force sensors' touch sites, each under a quarter of the sole, named by
    the foot (``l``, ``r``), then left or right (``l``, ``r``), then back or front (``b``,
    ``f``)."""
    g = w.model.geometry
    hl, hw, ht = g.foot_half_length_m, g.foot_half_width_m, g.foot_half_thickness_m
    fx, sole = g.foot_forward_m, -g.ankle_height_m
    sites = []
    letter = side.lower()
    for ny, y_name in ((1.0, "l"), (-1.0, "r")):
        for nx, x_name in ((-1.0, "b"), (1.0, "f")):
            name = f"{letter}{y_name}{x_name}"
            sites.append(
                f'<site name="{w.p}/site:{name}" type="box" group="4" '
                f'pos="{_f(fx + nx * hl / 2, ny * hw / 2, sole)}" '
                f'size="{_f(hl / 2 + 1e-3, hw / 2 + 1e-3, ht * 1.5)}"/>'
            )
    return "".join(sites)


def _arm(w: _Writer, side: str) -> str:
    g = w.model.geometry
    sign = 1.0 if side == "L" else -1.0
    r = g.foot_half_width_m * 0.45
    upper = w.geom(
        "arm",
        "upper_arm_" + side,
        f'type="capsule" fromto="{_f(0, 0, -r, 0, 0, -g.upper_arm_m)}" size="{r:.6g}"',
        LIMB_RGBA,
        g.upper_arm_kg,
    )
    fore = w.geom(
        "arm",
        "forearm_" + side,
        f'type="capsule" fromto="{_f(0, 0, 0, 0, 0, -g.forearm_m + r)}" size="{r * 0.9:.6g}"',
        LIMB_RGBA,
        g.forearm_kg * 0.7,
    )
    hand = w.geom(
        "hand", "hand_" + side, f'type="sphere" size="{r * 1.1:.6g}"', LIMB_RGBA, g.forearm_kg * 0.3
    )
    return f"""
<body name="{w.p}/shoulder_{side}" pos="{_f(0, sign * g.shoulder_y_m, g.shoulder_z_m)}">
 {_inertial(g.joint_link_kg, r)}{w.joint("Shoulder" + side, (0, -1, 0))}
 <body name="{w.p}/upper_arm_{side}">
  {w.joint("ArmUpper" + side, (1, 0, 0))}
  {upper}
  <body name="{w.p}/forearm_{side}" pos="{_f(0, 0, -g.upper_arm_m)}">
   {w.joint("ArmLower" + side, (0, -1, 0))}
   {fore}
   <body name="{w.p}/hand_{side}" pos="{_f(0, 0, -g.forearm_m)}">
    {hand}
   </body>
  </body>
 </body>
</body>"""


def build_humanoid(
    model: RobotModel,
    *,
    prefix: str,
    rgba: str,
    contype: int,
    conaffinity: int,
    pose: tuple[float, float, float],
    jersey: str | None = None,
) -> RobotMjcf:
    """The robot's body tree (root ``<prefix>/torso`` with a free joint, standing at ``pose`` =
    (x, y, yaw) in the world frame), its actuators and sensors. ``jersey``: the material of the
    team shirt, a plate on the chest and one on the back (:mod:`simulator.world.jersey`); None:
    a white chest plate."""
    w = _Writer(model, prefix, contype, conaffinity)
    x, y, yaw = pose
    g = model.geometry
    p = prefix
    tx, ty, tz = g.torso_half_size_m
    cam = model.camera
    fovy_deg = math.degrees(2 * math.atan(math.tan(cam.fov_rad / 2) * cam.height / cam.width))
    hr = g.head_radius_m
    cz = g.torso_centre_z_m
    torso = w.geom(
        "torso", "torso", f'type="box" pos="0 0 {cz:.6g}" size="{_f(tx, ty, tz)}"', rgba, g.torso_kg
    )
    chest = _chest(w, model, jersey)
    marker = w.visual(
        "marker",
        f'type="cylinder" pos="0 0 {hr * 0.95:.6g}" size="{_f(hr * 0.6, hr * 0.08)}"',
        rgba,
    )
    camera = (
        f'<camera name="{p}/{cam.name}" pos="{_f(g.camera_forward_m, 0, 0)}" xyaxes="0 -1 0 0 0 1" '
        f'fovy="{fovy_deg:.6g}"/>'
    )
    body = f"""
<body name="{p}/torso" pos="{_f(x, y, model.standing_height_m)}" euler="0 0 {yaw:.9g}">
 <freejoint name="{p}/root"/>
 {torso}{chest}
 <site name="{p}/site:imu" pos="0 0 {g.torso_centre_z_m:.6g}" size="0.01"/>
 {_leg(w, "L")}{_leg(w, "R")}{_arm(w, "L")}{_arm(w, "R")}
 <body name="{p}/neck" pos="0 0 {g.neck_z_m:.6g}">
  {_inertial(g.joint_link_kg, hr / 3)}{w.joint("Neck", (0, 0, 1))}
  <body name="{p}/head" pos="0 0 {g.head_centre_z_m:.6g}">
   {w.joint("Head", (0, 1, 0))}
   {w.geom("head", "head", f'type="sphere" size="{hr:.6g}"', HEAD_RGBA, g.head_kg)}
   {marker}{camera}
  </body>
 </body>
</body>"""
    actuators = "".join(actuator_xml(f"{p}/{m.name}", f"{p}/{m.name}", m) for m in model.motors)
    return RobotMjcf(body=body, actuators=actuators, sensors=_sensors(model, p))


def _chest(w: _Writer, model: RobotModel, jersey: str | None) -> str:
    """The chest's visuals: the jersey's two plates wearing ``jersey`` (a material), or without
    one a white chest plate."""
    g = model.geometry
    p = w.p
    tx, ty, tz = g.torso_half_size_m
    cz = g.torso_centre_z_m
    if jersey is None:
        return w.visual(
            "chest",
            f'type="box" pos="{_f(tx, 0, cz + tz * 0.3)}" '
            f'size="{_f(tx * 0.05, ty * 0.6, tz * 0.35)}"',
            "1 1 1 1",
        )
    # a plate on each side, turned so that the texture's rows run down and the number
    # reads from in front of it (x of the plate's frame out of the torso). The front one
    # where the white chest plate was and no larger: the head camera looking down at the
    # feet sees its top edge, and a taller one put red in the ring round a ball at the
    # feet (the stub's ball finder lost it); the back one larger
    plates = (
        ("front", 1.0, "0 1 0 0 0 1", cz + tz * 0.3, _f(ty * 0.6, tz * 0.35, tx * 0.05)),
        ("back", -1.0, "0 -1 0 0 0 1", cz, _f(ty * 0.75, tz * 0.6, tx * 0.05)),
    )
    return "".join(
        f'<geom name="{p}/visual:jersey_{side}" type="box" pos="{_f(sign * tx, 0, z)}" '
        f'xyaxes="{axes}" size="{half}" material="{jersey}" mass="0" contype="0" '
        f'conaffinity="0" group="1"/>'
        for side, sign, axes, z, half in plates
    )


def _sensors(model: RobotModel, p: str) -> str:
    """The IMU's accelerometer and gyro, the body's velocity, the feet's touch sensors."""
    return (
        f'<accelerometer name="{p}/Accelerometer" site="{p}/site:imu"/>'
        f'<gyro name="{p}/Gyro" site="{p}/site:imu"/>'
        f'<subtreelinvel name="{p}/com_velocity" body="{p}/torso"/>'
        + "".join(f'<touch name="{p}/{n}" site="{p}/site:{n}"/>' for n in model.force_sensors)
    )


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotModel(MotorLookup):
    """A built-in robot model: its shape, motors and sensors."""

    name: str
    field_class: str  # "kid" | "adult"
    geometry: HumanoidGeometry
    motors: tuple[MotorSpec, ...]
    joint_armature: float
    camera: CameraSpec = CameraSpec()
    force_sensors: tuple[str, ...] = FORCE_SENSORS
    # the robot stands crouched (``LegUpper = q, LegLower = 2 q, Ankle = q``: torso upright, feet
    # flat) with q = ``crouch_rad``; 0 for the built-in robots, which stand straight
    crouch_rad: float = 0.0
    # a box on each foot above its sole, (x, z of its centre, half length, half width, half
    # height) in the foot's frame (x forward, z up, the ankle at 0); None for the built-in robots.
    # The league's test robot carries its ankle servos there
    ankle_box_m: tuple[float, float, float, float, float] | None = None
    # the thigh and the shank as boxes instead of capsules, (half depth, half width, centre
    # forward of the leg's axis, length the shank's reaches above the knee), each along its
    # segment; None for the built-in robots. The league's test robot's legs are the Darwin-OP's
    # boxes, as wide as the knee a ball meets
    leg_box_m: tuple[float, float, float, float] | None = None

    @property
    def standing_height_m(self) -> float:
        """Height of the root body's origin above the ground in the standing pose."""
        g = self.geometry
        if not self.crouch_rad:
            return g.standing_height_m
        legs = (g.thigh_m + g.shank_m) * math.cos(self.crouch_rad)
        return -g.hip_z_m + legs + g.ankle_height_m

    @property
    def wears_jersey(self) -> bool:
        """The built-in robots wear the team's jersey on the chest and the back."""
        return True

    @property
    def devices(self) -> DeviceNames:
        """The league's sample robot's names: ``<motor>S``, ``Accelerometer``, ``Gyro``."""
        return DeviceNames.league(
            self.motor_names, camera=self.camera.name, forces=self.force_sensors
        )

    @property
    def standing_pose_rad(self) -> tuple[float, ...]:
        """Joint positions (``motor_names`` order) the robot stands in when placed: all zero, or
        the crouch of ``crouch_rad``."""
        q = self.crouch_rad
        crouch = {"LegUpper": q, "LegLower": 2.0 * q, "Ankle": q}
        return tuple(crouch.get(m.name[:-1], 0.0) for m in self.motors)

    def mjcf(
        self,
        *,
        prefix: str,
        rgba: str,
        contype: int,
        conaffinity: int,
        pose: tuple[float, float, float],
        jersey: str | None = None,
    ) -> RobotMjcf:
        """``jersey``: the material of the team shirt worn on the chest and back (None: a
        white chest plate)."""
        return build_humanoid(
            self,
            prefix=prefix,
            rgba=rgba,
            contype=contype,
            conaffinity=conaffinity,
            pose=pose,
            jersey=jersey,
        )
