"""The goal entity: two posts, a crossbar, a back bar and nets (thin boxes with
the look's net texture, see-through) behind a goal line.

Each net box is turned so that its thin side is its local z: MuJoCo lays a 2D texture on a
box's faces by the local x and y, so only the faces normal to z show the net's full mesh.
"""

from __future__ import annotations

from contracts import FieldGeometry
from simulator.world.look import NET_TEXTURE

POST_RGBA = "1 1 1 1"
NET_HALF_THICKNESS_M = 0.01


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
            f'material="{NET_TEXTURE}" {col}/>'
        )
    geoms.append(
        f'<geom name="{name}:crossbar" type="cylinder" '
        f'fromto="{x:.6g} {-half_w:.6g} {h + r:.6g} {x:.6g} {half_w:.6g} {h + r:.6g}" '
        f'size="{r:.6g}" rgba="{POST_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:net_back" type="box" pos="{back_x + sign * t:.6g} 0 {h / 2:.6g}" '
        f'size="{h / 2:.6g} {half_w + r:.6g} {t}" euler="0 1.5707963 0" '
        f'material="{NET_TEXTURE}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:back_bar" type="cylinder" '
        f'fromto="{back_x:.6g} {-half_w:.6g} {h:.6g} {back_x:.6g} {half_w:.6g} {h:.6g}" '
        f'size="{r / 2:.6g}" rgba="{POST_RGBA}" {col}/>'
    )
    geoms.append(
        f'<geom name="{name}:net_top" type="box" pos="{mid_x:.6g} 0 {h + t:.6g}" '
        f'size="{d / 2:.6g} {half_w + r:.6g} {t}" material="{NET_TEXTURE}" {col}/>'
    )
    return "".join(geoms)
