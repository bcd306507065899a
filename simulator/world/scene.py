"""Assembles the world MJCF from its entities (field, goals, ball, robots) and compiles it.

Collision filtering: each robot ``i`` gets its own bit ``1 << i`` as ``contype`` and every robot
bit as ``conaffinity`` (:func:`robot_conaffinity`), so a robot's parts collide with other robots,
the ball, the turf, the goals and its own non-adjacent links (the exclusion rule is
:mod:`simulator.world.selfcollision`'s). Static geoms and the ball have bits of their own.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import mujoco
import numpy as np

from contracts import FieldGeometry, RobotId, TeamColor
from simulator.world.ball import (
    BALL_GEOM,
    BALL_JOINT,
    BALL_TURF_PAIR,
    ball_body,
    ball_damping,
)
from simulator.world.field import field_bodies, line_mesh_xml
from simulator.world.goal import GOALS, goal_bodies, net_mesh_xml
from simulator.world.jersey import apply_jerseys, jersey_assets, jersey_material
from simulator.world.look import Look, apply_look, look_assets, look_for
from simulator.world.robots import robot_model
from simulator.world.selfcollision import exclude_xml
from simulator.world.types import RobotPlacement, robot_prefix

STATIC_BIT = 1 << 30
BALL_BIT = 1 << 29
MAX_ROBOTS = 29
TEAM_RGBA = {TeamColor.RED: "0.85 0.12 0.1 1", TeamColor.BLUE: "0.1 0.25 0.9 1"}


def _team_rgb(team: TeamColor) -> tuple[float, float, float]:
    r, g, b, _ = (float(v) for v in TEAM_RGBA[team].split())
    return (r, g, b)


def robot_jerseys(
    robots: Iterable[tuple[str, int]],
) -> list[tuple[str, int, tuple[float, float, float]]]:
    """The jerseys of robots given as (team colour value, number), as the match's world filled
    them (prefix, number, team colour: :func:`simulator.world.jersey.apply_jerseys`)."""
    return [
        (robot_prefix(RobotId(TeamColor(team), number)), number, _team_rgb(TeamColor(team)))
        for team, number in robots
    ]


def robot_conaffinity(robots: int) -> int:
    """The ``conaffinity`` of every robot geom in a world of ``robots`` robots."""
    return ((1 << robots) - 1) | STATIC_BIT | BALL_BIT


def ball_touch_sensor(placement: RobotPlacement) -> str:
    """Name of the sensor counting a robot's contacts with the ball (computed by MuJoCo)."""
    return f"{robot_prefix(placement.id)}/ball_touch"


def scene_xml(
    field: FieldGeometry,
    robots: Sequence[RobotPlacement],
    *,
    physics_dt_s: float,
    look: Look | None = None,
    ball_turf_pair: bool = False,
) -> str:
    """The world MJCF (its look's textures still blank: :func:`compile_scene` fills them).
    Raises UnknownModelError for a model name we do not ship."""
    look = look if look is not None else look_for(0)
    if len(robots) > MAX_ROBOTS:
        raise ValueError(f"at most {MAX_ROBOTS} robots, got {len(robots)}")
    robot_bits = (1 << len(robots)) - 1
    static = (STATIC_BIT, BALL_BIT | robot_bits)
    ball = (BALL_BIT, STATIC_BIT | robot_bits)
    bodies = [
        field_bodies(field, static_bits=static),
        *(goal_bodies(field, sign=sign, name=name, static_bits=static) for sign, name in GOALS),
        ball_body(field, bits=ball),
    ]
    actuators = []
    sensors = []
    excludes = []
    assets: dict[str, str] = {}
    for i, placement in enumerate(robots):
        model = robot_model(placement.model)
        bit = 1 << i
        prefix = robot_prefix(placement.id)
        jersey = model.wears_jersey  # built-in robots, team models whose manifest says where
        parts = model.mjcf(
            prefix=prefix,
            rgba=TEAM_RGBA[placement.id.team],
            contype=bit,
            conaffinity=robot_conaffinity(len(robots)),
            pose=(placement.x_m, placement.y_m, placement.yaw_rad),
            jersey=jersey_material(prefix) if jersey else None,
        )
        if jersey:
            assets[jersey_material(prefix)] = jersey_assets(prefix)
        bodies.append(parts.body)
        excludes.append(exclude_xml(model, robot_prefix(placement.id)))
        if parts.assets:
            assets.setdefault(parts.asset_key, parts.assets)
        actuators.append(parts.actuators)
        sensors.append(parts.sensors)
        sensors.append(
            f'<contact name="{ball_touch_sensor(placement)}" subtree1="{robot_prefix(placement.id)}'
            f'/torso" geom2="{BALL_GEOM}" data="found" num="1"/>'
        )
    merged = line_mesh_xml(field) + "".join(
        net_mesh_xml(field, sign=sign, name=name) for sign, name in GOALS
    )
    return f"""<mujoco model="hlvs-{field.field_class.value}">
<compiler angle="radian" autolimits="true"/>
<option timestep="{physics_dt_s!r}" integrator="implicitfast" cone="pyramidal"/>
<visual>
 <global offwidth="1920" offheight="1080"/>
 <quality shadowsize="2048" offsamples="0"/>
 <headlight ambient="0.35 0.35 0.35" diffuse="0 0 0" specular="0 0 0"/>
 <map znear="0.01" zfar="100"/>
</visual>
<asset>{look_assets(look)}{merged}{"".join(assets.values())}</asset>
<worldbody>{"".join(bodies)}</worldbody>
<contact>{_ball_turf_pair() if ball_turf_pair else ""}{"".join(excludes)}</contact>
<actuator>{"".join(actuators)}</actuator>
<sensor>{"".join(sensors)}</sensor>
</mujoco>"""


def _ball_turf_pair() -> str:
    """The ball's contact with the turf as an explicit pair (MuJoCo then skips the pair's
    dynamic contact), whose parameters the league's test world sets apart from the ball's with
    the robots (:func:`simulator.world.ball.use_league_contacts`); matches have no such pair."""
    return f'<pair name="{BALL_TURF_PAIR}" geom1="{BALL_GEOM}" geom2="turf" condim="3"/>'


def compile_scene(
    field: FieldGeometry,
    robots: Sequence[RobotPlacement],
    *,
    physics_dt_s: float,
    look: Look | None = None,
    ball_turf_pair: bool = False,
) -> mujoco.MjModel:
    """Compile the world model, with the ball's per-axis damping applied and ``look`` (default:
    the look of texture seed 0) in its textures and lights."""
    look = look if look is not None else look_for(0)
    model = mujoco.MjModel.from_xml_string(
        scene_xml(
            field, robots, physics_dt_s=physics_dt_s, look=look, ball_turf_pair=ball_turf_pair
        )
    )
    apply_look(model, look)
    apply_jerseys(
        model,
        ((robot_prefix(p.id), p.id.number, _team_rgb(p.id.team)) for p in robots),
    )
    linear, angular = ball_damping(field)
    adr = int(model.joint(BALL_JOINT).dofadr[0])
    model.dof_damping[adr : adr + 3] = linear
    model.dof_damping[adr + 3 : adr + 6] = angular
    return model


def body_names(model: mujoco.MjModel) -> list[str]:
    return [model.body(i).name for i in range(model.nbody)]


def geom_names(model: mujoco.MjModel) -> list[str]:
    return [model.geom(i).name for i in range(model.ngeom)]


def as_int_array(values: Sequence[int]) -> np.ndarray:
    return np.asarray(values, dtype=np.int64)
