"""The goal entity: two posts, a crossbar, a back bar and nets behind a goal line.

Each net is a thin box that the ball and robots collide with, invisible (alpha 0: renderers
skip it), and a mesh of cords that cameras see (visual geoms: no contacts, no mass), dark
cords of :data:`~simulator.world.look.NET_CORD_M` every
:data:`~simulator.world.look.NET_MESH_M` with open holes, as the league's net texture.
"""

from __future__ import annotations

from contracts import FieldGeometry
from simulator.world.look import NET_CORD_M, NET_MESH_M, NET_RGBA

POST_RGBA = "0.82 0.82 0.82 1"  # white paint: bright under the lights, not clipped
NET_HALF_THICKNESS_M = 0.01
NET_BOX_RGBA = "0.3 0.3 0.3 0"  # the collision boxes of the nets are not drawn


def _spans(low: float, high: float) -> list[float]:
    """Cord positions from ``low`` to ``high`` (both ends), about NET_MESH_M apart."""
    n = max(1, round(abs(high - low) / NET_MESH_M))
    return [low + (high - low) * k / n for k in range(n + 1)]


def _cord(name: str, centre: tuple[float, float, float], half: tuple[float, float, float]) -> str:
    return (
        f'<geom name="{name}" type="box" pos="{centre[0]:.6g} {centre[1]:.6g} {centre[2]:.6g}" '
        f'size="{half[0]:.6g} {half[1]:.6g} {half[2]:.6g}" rgba="{NET_RGBA}" contype="0" '
        f'conaffinity="0" group="1" mass="0"/>'
    )


def _net_cords(
    name: str, axes: tuple[int, int], ranges: tuple[tuple[float, float], tuple[float, float]],
    fixed: tuple[int, float],
) -> list[str]:  # fmt: skip
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
            out.append(_cord(f"{name}_{along}{k}", (centre[0], centre[1], centre[2]),
                             (half[0], half[1], half[2])))  # fmt: skip
    return out


def goal_bodies(f: FieldGeometry, *, sign: float, name: str, static_bits: tuple[int, int]) -> str:
    """Static geoms of the goal behind the goal line at ``x = sign * half_length``."""
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
        geoms += _net_cords(
            f"{name}:net_side_{label}_cord", (0, 2), ((x, back_x), (0.0, h)),
            (1, ys * (half_w + r + t)),
        )  # fmt: skip
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
    geoms += _net_cords(
        f"{name}:net_back_cord", (1, 2), ((-half_w - r, half_w + r), (0.0, h)),
        (0, back_x + sign * t),
    )  # fmt: skip
    geoms.append(
        f'<geom name="{name}:back_bar" type="cylinder" '
        f'fromto="{back_x:.6g} {-half_w:.6g} {h:.6g} {back_x:.6g} {half_w:.6g} {h:.6g}" '
        f'size="{r / 2:.6g}" rgba="{POST_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:net_top" type="box" pos="{mid_x:.6g} 0 {h + t:.6g}" '
        f'size="{d / 2:.6g} {half_w + r:.6g} {t}" rgba="{NET_BOX_RGBA}" {col}/>'
    )
    geoms += _net_cords(
        f"{name}:net_top_cord", (0, 1), ((x, back_x), (-half_w - r, half_w + r)), (2, h + t)
    )
    return "".join(geoms)
