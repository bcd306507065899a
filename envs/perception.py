"""Idealised perception: what the head camera would see, computed from the world, no rendering.

Camera frame: origin at the camera, ``x`` along the optical axis (forward), ``y`` to the left,
``z`` up in the image. An object is visible when it lies in front of the camera (at least
``NEAR_M``, at most ``max_range_m``) within the horizontal and vertical fields of view. Rows
(all float32, in metres):

- ``ball``: ``[visible, x, y, z]`` of the ball centre;
- ``goal_posts``: 4 rows ``[visible, x, y, z]`` of the post feet on the ground, in the order
  opponent goal left post, opponent goal right post, own goal left post, own goal right post
  (left and right as seen by a robot facing the opponent goal);
- ``lines``: one row per field line segment ``[visible, x1, y1, z1, x2, y2, z2]``, the part of
  the segment inside the view (touch lines, goal lines, halfway line, goal and penalty areas,
  the centre circle as 16 chords: 33 rows);
- ``robots``: one row per other robot ``[visible, x, y, z, teammate]`` of its torso.

Invisible rows are all zero. With ``noise`` > 0 every visible point gets Gaussian noise of
standard deviation ``noise`` x its distance (a stereo-like error growing with distance), drawn
from the generator given (the environment's own, so seeded episodes repeat).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from contracts import FieldGeometry

FloatArray = npt.NDArray[np.float64]
NEAR_M = 0.05
CIRCLE_CHORDS = 16
LINE_COUNT = 17 + CIRCLE_CHORDS


def field_segments(field: FieldGeometry) -> FloatArray:
    """(LINE_COUNT, 2, 3) end points of the field's line segments in the world frame."""
    L, W = field.half_length_m, field.half_width_m  # noqa: N806
    segments: list[tuple[tuple[float, float], tuple[float, float]]] = [
        ((-L, W), (L, W)),
        ((-L, -W), (L, -W)),
        ((-L, -W), (-L, W)),
        ((L, -W), (L, W)),
        ((0.0, -W), (0.0, W)),
    ]
    for sign in (-1.0, 1.0):
        for depth, half in (
            (field.goal_area_length_m, field.goal_area_width_m / 2),
            (field.penalty_area_length_m, field.penalty_area_width_m / 2),
        ):
            x_in = sign * (L - depth)
            segments += [
                ((sign * L, half), (x_in, half)),
                ((sign * L, -half), (x_in, -half)),
                ((x_in, -half), (x_in, half)),
            ]
    r = field.centre_circle_radius_m
    for i in range(CIRCLE_CHORDS):
        a0, a1 = 2 * math.pi * i / CIRCLE_CHORDS, 2 * math.pi * (i + 1) / CIRCLE_CHORDS
        segments.append(
            ((r * math.cos(a0), r * math.sin(a0)), (r * math.cos(a1), r * math.sin(a1)))
        )
    out = np.zeros((len(segments), 2, 3))
    for i, (a, b) in enumerate(segments):
        out[i, 0, :2] = a
        out[i, 1, :2] = b
    return out


def goal_post_feet(field: FieldGeometry, attack_sign: float) -> FloatArray:
    """(4, 3) post feet: opponent left, opponent right, own left, own right."""
    half = field.goal_width_m / 2 + field.goal_post_radius_m
    x_opp, x_own = attack_sign * field.half_length_m, -attack_sign * field.half_length_m
    left = attack_sign * half  # "left" for a robot facing the opponent goal
    return np.array([[x_opp, left, 0.0], [x_opp, -left, 0.0], [x_own, left, 0.0],
                     [x_own, -left, 0.0]])  # fmt: skip


@dataclass(frozen=True, slots=True, kw_only=True)
class CameraView:
    """A camera pose in the world and its field of view."""

    position: FloatArray  # (3,) world
    rotation: FloatArray  # (3, 3) columns: forward, left, up in world coordinates
    hfov_rad: float
    vfov_rad: float
    max_range_m: float

    @classmethod
    def from_mujoco(
        cls,
        cam_xpos: FloatArray,
        cam_xmat: FloatArray,
        *,
        hfov_rad: float,
        aspect: float,
        max_range_m: float,
    ) -> CameraView:
        """From MuJoCo's camera frame (looks along -z, y up, x right)."""
        m = np.asarray(cam_xmat, dtype=np.float64).reshape(3, 3)
        rotation = np.stack([-m[:, 2], -m[:, 0], m[:, 1]], axis=1)
        vfov = 2 * math.atan(math.tan(hfov_rad / 2) / aspect)
        return cls(position=np.array(cam_xpos, dtype=np.float64), rotation=rotation,
                   hfov_rad=hfov_rad, vfov_rad=vfov, max_range_m=max_range_m)  # fmt: skip

    def to_camera(self, points: FloatArray) -> FloatArray:
        """World points (..., 3) in the camera frame."""
        out: FloatArray = (points - self.position) @ self.rotation
        return out

    def constraints(self) -> tuple[FloatArray, FloatArray]:
        """Half-spaces ``a . p + b >= 0`` (camera frame) of the view volume."""
        th, tv = math.tan(self.hfov_rad / 2), math.tan(self.vfov_rad / 2)
        a = np.array([[th, -1, 0], [th, 1, 0], [tv, 0, -1], [tv, 0, 1], [1, 0, 0], [-1, 0, 0]],
                     dtype=np.float64)  # fmt: skip
        b = np.array([0, 0, 0, 0, -NEAR_M, self.max_range_m], dtype=np.float64)
        return a, b

    def points(self, world_points: FloatArray) -> FloatArray:
        """(n, 4) rows ``[visible, x, y, z]`` for world points (n, 3)."""
        cam = self.to_camera(world_points)
        a, b = self.constraints()
        inside = np.all(cam @ a.T + b >= 0, axis=1)
        out = np.zeros((len(cam), 4))
        out[inside, 0] = 1.0
        out[inside, 1:] = cam[inside]
        return out

    def segments(self, world_segments: FloatArray) -> FloatArray:
        """(n, 7) rows ``[visible, x1, y1, z1, x2, y2, z2]``: each segment clipped to the view
        (Cyrus-Beck against the six planes of the view volume)."""
        p0 = self.to_camera(world_segments[:, 0, :])
        p1 = self.to_camera(world_segments[:, 1, :])
        a, b = self.constraints()
        f0 = p0 @ a.T + b  # (n, planes)
        f1 = p1 @ a.T + b
        with np.errstate(divide="ignore", invalid="ignore"):
            t = np.where(f0 != f1, f0 / (f0 - f1), 0.0)
        entering = (f0 < 0) & (f1 >= 0)
        leaving = (f0 >= 0) & (f1 < 0)
        outside = np.any((f0 < 0) & (f1 < 0), axis=1)
        t_lo = np.max(np.where(entering, t, 0.0), axis=1)
        t_hi = np.min(np.where(leaving, t, 1.0), axis=1)
        visible = ~outside & (t_lo < t_hi)
        d = p1 - p0
        out = np.zeros((len(p0), 7))
        out[visible, 0] = 1.0
        out[visible, 1:4] = p0[visible] + t_lo[visible, None] * d[visible]
        out[visible, 4:7] = p0[visible] + t_hi[visible, None] * d[visible]
        return out


def add_noise(rows: FloatArray, columns: slice, noise: float, rng: np.random.Generator) -> None:
    """Gaussian noise (std ``noise`` x distance) on the visible rows' point columns, in place."""
    if noise <= 0:
        return
    visible = rows[:, 0] > 0
    if not visible.any():
        return
    block = rows[visible, columns]
    for start in range(0, block.shape[1], 3):
        point = block[:, start : start + 3]
        distance = np.linalg.norm(point, axis=1, keepdims=True)
        point += rng.normal(0.0, 1.0, size=point.shape) * noise * distance
    rows[visible, columns] = block
