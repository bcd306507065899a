"""The pitch entity: turf (field plus border strip), visual lines, lights and the video camera.

The turf's and the lines' textures and the lights come from the look
(:mod:`simulator.world.look`). The robot cameras draw the lines as one mesh
(:func:`line_mesh_xml`, :mod:`simulator.world.merged`).

The turf is the league's soft grass. Its contact parameters in the league's Webots world
(RoboCup-Humanoid-TC/hlvs_webots ``worlds/robocup.wbt``: ``ContactProperties`` of material
``grass``: ``coulombFriction 0.5``, ``softCFM 0.03``, ``softERP`` left at 0.2, ``basicTimeStep``
8 ms) are ODE's soft contact, which is a spring and damper per contact point (ODE manual,
"Soft constraint and constraint force mixing": ``ERP = h kp / (h kp + kd)``,
``CFM = 1 / (h kp + kd)``)::

    kp = ERP / (h CFM) = 0.2 / (0.008 s * 0.03) = 833 N/m      per contact point
    kd = (1 - ERP) / CFM = 0.8 / 0.03          = 26.7 N s/m

A KidSize robot of 4.9 kg (``kid-default``) standing on its eight cleats sinks
``m g / (8 kp)`` = 7.2 mm; on one foot twice that (:data:`GRASS_SINKAGE_M`).

MuJoCo's soft contacts are normalised by mass and let part of the unconstrained acceleration
through: ``a1 + d (b v + k r) = (1 - d) a0`` (MuJoCo documentation, Computation, "Soft
constraints"; ``d`` the impedance of ``solimp``, ``k`` and ``b`` from ``solref``), and the
friction of a contact gets the same softness: a loaded contact creeps sideways at a speed
proportional to ``(1 - d) / b``. A linear spring of the league's sinkage (constant ``d``) made a
standing robot's feet creep 10 to 20 cm in a second under a 0.1 g push, rigid turf 1.8 mm. The
grass is therefore built from the impedance: ``d`` rises from 0 to 0.99 over the first 9 mm of
depth (``solimp`` width 9 mm, midpoint 0.5, power 2), which is the soft give of the grass, and a
small stiffness and a large damping (``solref`` in the direct form, -30 s^-2 and -80 s^-1) hold a
contact where ``d`` is high, so that friction stays firm. Measured
(``tests/unit/world/test_world_turf.py``): a standing ``kid-default`` sinks 6.9 mm (the league's
7.2 mm), the same for every robot (MuJoCo's softness does not depend on mass), its feet creep
3.9 mm under the 0.1 g push, and a block sliding on the turf feels a friction force 0.48 times
its normal force (configured 0.5). The ball keeps its own contact parameters (higher priority,
:mod:`simulator.world.ball`). The league's ``bounce 0.5`` of robot-grass contacts is not
modelled (MuJoCo contacts do not restitute beyond their spring and damper).
"""

from __future__ import annotations

import functools
import math

from contracts import FieldGeometry
from simulator.world.look import (
    LINE_MESH_MATERIAL,
    LINE_TEXTURE,
    LINE_TILE_M,
    TURF_TEXTURE,
    light_xml,
)
from simulator.world.merged import MERGED_PREFIX, Box, box_mesh_xml, merged_geom_xml

TURF_FRICTION = 0.5
GRASS_SOLREF = (-30.0, -80.0)  # direct form: -stiffness (1/s^2), -damping (1/s)
GRASS_SOLIMP = (0.0, 0.99, 0.009, 0.5, 2.0)  # impedance 0 -> 0.99 over the first 9 mm of depth
GRASS_SINKAGE_M = 0.0072  # league's world: a 4.9 kg robot on eight contact points (see above)
LINE_HEIGHT_M = 0.001
CIRCLE_SEGMENTS = 48
LINES = "line:"  # the line geoms' names begin so


def _f(values: tuple[float, ...]) -> str:
    return " ".join(f"{v:.9g}" for v in values)


def _box(name: str, x: float, y: float, half_x: float, half_y: float,
         yaw: float = 0.0) -> tuple[str, Box]:  # fmt: skip
    return name, Box((x, y, LINE_HEIGHT_M), (half_x, half_y, LINE_HEIGHT_M), yaw)


def _line_xml(name: str, box: Box) -> str:
    (x, y, z), (half_x, half_y, half_z) = box.centre, box.half
    return (
        f'<geom name="{LINES}{name}" type="box" pos="{x:.9g} {y:.9g} {z}" '
        f'size="{half_x:.9g} {half_y:.9g} {half_z}" euler="0 0 {box.yaw:.9g}" '
        f'material="{LINE_TEXTURE}" contype="0" conaffinity="0" group="1" mass="0"/>'
    )


@functools.lru_cache(maxsize=4)
def line_mesh_xml(f: FieldGeometry) -> str:
    """The lines as one mesh (:mod:`simulator.world.merged`; their bottoms left out), for the
    assets."""
    boxes = [box for _, box in _lines(f)]
    return box_mesh_xml(MERGED_PREFIX + LINES, boxes, texrepeat=1.0 / LINE_TILE_M, bottoms=False)


def _lines(f: FieldGeometry) -> list[tuple[str, Box]]:
    w = f.line_width_m / 2
    lx, ly = f.half_length_m, f.half_width_m
    out = [
        _box("touch_left", 0.0, ly, lx + w, w),
        _box("touch_right", 0.0, -ly, lx + w, w),
        _box("halfway", 0.0, 0.0, w, ly),
        _box("centre_mark", 0.0, 0.0, w * 2, w),
    ]
    for sign, side in ((-1.0, "l"), (1.0, "r")):
        out.append(_box(f"goal_line_{side}", sign * lx, 0.0, w, ly + w))
        for name, length, width in (
            ("goal_area", f.goal_area_length_m, f.goal_area_width_m),
            ("penalty_area", f.penalty_area_length_m, f.penalty_area_width_m),
        ):
            inner_x = sign * (lx - length)
            out.append(_box(f"{name}_{side}", inner_x, 0.0, w, width / 2 + w))
            for ys, yn in ((1.0, "a"), (-1.0, "b")):
                cx = sign * (lx - length / 2)
                out.append(_box(f"{name}_{side}_{yn}", cx, ys * width / 2, length / 2, w))
        mark_x = sign * f.penalty_mark_x_m
        out.append(_box(f"penalty_mark_{side}_x", mark_x, 0.0, 0.05, w))
        out.append(_box(f"penalty_mark_{side}_y", mark_x, 0.0, w, 0.05))
    r = f.centre_circle_radius_m
    seg = math.pi * r / CIRCLE_SEGMENTS * 1.02
    for i in range(CIRCLE_SEGMENTS):
        a = 2 * math.pi * (i + 0.5) / CIRCLE_SEGMENTS
        out.append(_box(f"circle_{i}", r * math.cos(a), r * math.sin(a), w, seg, a))
    return out


def field_bodies(f: FieldGeometry, *, static_bits: tuple[int, int]) -> str:
    """Turf, lines, lights and the overview camera (children of the world body)."""
    contype, conaffinity = static_bits
    tx, ty = f.turf_half_length_m, f.turf_half_width_m
    distance = ty + 2.3 * (tx / 5.5)
    height = 0.75 * distance
    norm = math.hypot(distance, height)
    parts = [
        f'<geom name="turf" type="plane" size="{tx:.6g} {ty:.6g} 0.1" material="{TURF_TEXTURE}" '
        f'friction="{TURF_FRICTION} 0.005 0.0001" priority="1" contype="{contype}" '
        f'conaffinity="{conaffinity}" solref="{_f(GRASS_SOLREF)}" solimp="{_f(GRASS_SOLIMP)}"/>',
        light_xml(),
        f'<camera name="overview" pos="0 {-distance:.6g} {height:.6g}" '
        f'xyaxes="1 0 0 0 {height / norm:.6g} {distance / norm:.6g}" fovy="55"/>',
    ]
    parts.extend(_line_xml(name, box) for name, box in _lines(f))
    parts.append(merged_geom_xml(MERGED_PREFIX + LINES, material=LINE_MESH_MATERIAL))
    return "".join(parts)
