"""The pitch entity: turf (field plus border strip), visual lines, lights and the video camera.

The turf's texture and the lights' strength come from the look (:mod:`simulator.world.look`).
"""

from __future__ import annotations

import math

from contracts.field import FieldGeometry
from simulator.world.look import TURF_TEXTURE

TURF_FRICTION = 0.5
LINE_HEIGHT_M = 0.001
LINE_RGBA = "1 1 1 1"
CIRCLE_SEGMENTS = 48


def _box(name: str, x: float, y: float, half_x: float, half_y: float, yaw: float = 0.0) -> str:
    return (
        f'<geom name="line:{name}" type="box" pos="{x:.9g} {y:.9g} {LINE_HEIGHT_M}" '
        f'size="{half_x:.9g} {half_y:.9g} {LINE_HEIGHT_M}" euler="0 0 {yaw:.9g}" '
        f'rgba="{LINE_RGBA}" contype="0" conaffinity="0" group="1" mass="0"/>'
    )


def _lines(f: FieldGeometry) -> list[str]:
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
        f'conaffinity="{conaffinity}"/>',
        '<light name="sun" directional="true" pos="0 0 10" dir="0.2 0.3 -1" '
        'diffuse="0.7 0.7 0.7" castshadow="false"/>',
        '<light name="fill" directional="true" pos="0 0 10" dir="-0.2 -0.3 -1" '
        'diffuse="0.3 0.3 0.3" castshadow="false"/>',
        f'<camera name="overview" pos="0 {-distance:.6g} {height:.6g}" '
        f'xyaxes="1 0 0 0 {height / norm:.6g} {distance / norm:.6g}" fovy="55"/>',
    ]
    parts.extend(_lines(f))
    return "".join(parts)
