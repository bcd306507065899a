"""The goal entity: two posts, a crossbar, a back bar and nets behind a goal line.

Each net is a thin box that the ball and robots collide with, invisible (alpha 0: renderers
skip it), and a mesh of cords that cameras see (visual geoms: no contacts, no mass), dark
cords of :data:`~simulator.world.look.NET_CORD_M` every
:data:`~simulator.world.look.NET_MESH_M` with open holes, as the league's net texture. The
robot cameras draw each goal's cords as one mesh (:func:`net_mesh_xml`,
:mod:`simulator.world.merged`).
"""

from __future__ import annotations

import functools

from contracts import FieldGeometry
from simulator.world.look import NET_CORD_M, NET_MESH_M, NET_RGBA
from simulator.world.merged import MERGED_PREFIX, Box, box_mesh_xml, merged_geom_xml

POST_RGBA = "0.82 0.82 0.82 1"  # white paint: bright under the lights, not clipped
NET_HALF_THICKNESS_M = 0.01
NET_BOX_RGBA = "0.3 0.3 0.3 0"  # the collision boxes of the nets are not drawn
CORDS = "cord:"  # after the goal's name, the names of its nets' cords begin so
GOALS = ((-1.0, "goal_left"), (1.0, "goal_right"))  # (sign of x, name)


def _spans(low: float, high: float) -> list[float]:
    """Cord positions from ``low`` to ``high`` (both ends), about NET_MESH_M apart."""
    n = max(1, round(abs(high - low) / NET_MESH_M))
    return [low + (high - low) * k / n for k in range(n + 1)]


def _cord(name: str, box: Box) -> str:
    (x, y, z), (hx, hy, hz) = box.centre, box.half
    return (
        f'<geom name="{name}" type="box" pos="{x:.6g} {y:.6g} {z:.6g}" '
        f'size="{hx:.6g} {hy:.6g} {hz:.6g}" rgba="{NET_RGBA}" contype="0" '
        f'conaffinity="0" group="1" mass="0"/>'
    )


def _net_cords(
    name: str, axes: tuple[int, int], ranges: tuple[tuple[float, float], tuple[float, float]],
    fixed: tuple[int, float],
) -> list[tuple[str, Box]]:  # fmt: skip
    """The cords of one flat net: it spans ``ranges`` along the two ``axes`` (0 x, 1 y, 2 z)
    and sits at ``fixed`` (axis, coordinate); one cord along each axis at every mesh step of
    the other."""
    c = NET_CORD_M / 2
    out = []
    for along, across in ((0, 1), (1, 0)):
        lo, hi = ranges[along]
        for k, pos in enumerate(_spans(*ranges[across])):
            centre = [0.0, 0.0, 0.0]
            half = [c, c, c]
            centre[fixed[0]] = fixed[1]
            centre[axes[along]] = (lo + hi) / 2
            half[axes[along]] = abs(hi - lo) / 2
            centre[axes[across]] = pos
            # rounded as the geoms' XML rounds them: the mesh's boxes are the geoms'
            out.append((f"{name}_{along}{k}",
                        Box((_r(centre[0]), _r(centre[1]), _r(centre[2])),
                            (_r(half[0]), _r(half[1]), _r(half[2])))))  # fmt: skip
    return out


def _r(value: float) -> float:
    return float(f"{value:.6g}")


def _goal_cords(f: FieldGeometry, *, sign: float, name: str) -> list[tuple[str, Box]]:
    """Every cord of the goal's nets (sides, back, top), named."""
    r = f.goal_post_radius_m
    x = sign * f.half_length_m
    half_w = f.goal_width_m / 2 + r  # post centres
    h = f.goal_height_m
    back_x = sign * (f.half_length_m + f.goal_depth_m)
    t = NET_HALF_THICKNESS_M
    cords = []
    for ys, label in ((1.0, "a"), (-1.0, "b")):
        cords += _net_cords(
            f"{name}:{CORDS}side_{label}", (0, 2), ((x, back_x), (0.0, h)),
            (1, ys * (half_w + r + t)),
        )  # fmt: skip
    cords += _net_cords(
        f"{name}:{CORDS}back", (1, 2), ((-half_w - r, half_w + r), (0.0, h)),
        (0, back_x + sign * t),
    )  # fmt: skip
    cords += _net_cords(
        f"{name}:{CORDS}top", (0, 1), ((x, back_x), (-half_w - r, half_w + r)), (2, h + t)
    )
    return cords


@functools.lru_cache(maxsize=8)
def net_mesh_xml(f: FieldGeometry, *, sign: float, name: str) -> str:
    """The goal's cords as one mesh (:mod:`simulator.world.merged`), for the assets."""
    return box_mesh_xml(
        f"{MERGED_PREFIX}{name}:{CORDS}", [box for _, box in _goal_cords(f, sign=sign, name=name)]
    )


def goal_bodies(f: FieldGeometry, *, sign: float, name: str, static_bits: tuple[int, int]) -> str:
    """Static geoms of the goal behind the goal line at ``x = sign * half_length``: posts, bars,
    the nets' invisible boxes, their cords and the cords' mesh (:func:`net_mesh_xml`)."""
    contype, conaffinity = static_bits
    col = f'contype="{contype}" conaffinity="{conaffinity}"'
    r = f.goal_post_radius_m
    x = sign * f.half_length_m
    half_w = f.goal_width_m / 2 + r  # post centres
    h = f.goal_height_m
    d = f.goal_depth_m
    back_x = sign * (f.half_length_m + d)
    mid_x = sign * (f.half_length_m + d / 2)
    t = NET_HALF_THICKNESS_M
    geoms = []
    for ys, label in ((1.0, "a"), (-1.0, "b")):
        geoms.append(
            f'<geom name="{name}:post_{label}" type="cylinder" '
            f'fromto="{x:.6g} {ys * half_w:.6g} 0 {x:.6g} {ys * half_w:.6g} {h + 2 * r:.6g}" '
            f'size="{r:.6g}" rgba="{POST_RGBA}" {col}/>'
        )
        geoms.append(
            f'<geom name="{name}:net_side_{label}" type="box" '
            f'pos="{mid_x:.6g} {ys * (half_w + r + t):.6g} {h / 2:.6g}" '
            f'size="{d / 2:.6g} {h / 2:.6g} {t}" euler="1.5707963 0 0" '
            f'rgba="{NET_BOX_RGBA}" {col}/>'
        )
    geoms.append(
        f'<geom name="{name}:crossbar" type="cylinder" '
        f'fromto="{x:.6g} {-half_w:.6g} {h + r:.6g} {x:.6g} {half_w:.6g} {h + r:.6g}" '
        f'size="{r:.6g}" rgba="{POST_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:net_back" type="box" pos="{back_x + sign * t:.6g} 0 {h / 2:.6g}" '
        f'size="{h / 2:.6g} {half_w + r:.6g} {t}" euler="0 1.5707963 0" '
        f'rgba="{NET_BOX_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:back_bar" type="cylinder" '
        f'fromto="{back_x:.6g} {-half_w:.6g} {h:.6g} {back_x:.6g} {half_w:.6g} {h:.6g}" '
        f'size="{r / 2:.6g}" rgba="{POST_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:net_top" type="box" pos="{mid_x:.6g} 0 {h + t:.6g}" '
        f'size="{d / 2:.6g} {half_w + r:.6g} {t}" rgba="{NET_BOX_RGBA}" {col}/>'
    )
    geoms += [_cord(cord, box) for cord, box in _goal_cords(f, sign=sign, name=name)]
    geoms.append(merged_geom_xml(f"{MERGED_PREFIX}{name}:{CORDS}"))
    return "".join(geoms)
