"""Idealised perception: field of view, clipping, frames and noise, from the geometry alone."""

from __future__ import annotations

import math

import numpy as np

from contracts.field import KID_FIELD
from envs.perception import LINE_COUNT, CameraView, add_noise, field_segments, goal_post_feet


def _view(yaw: float = 0.0, height: float = 0.7) -> CameraView:
    c, s = math.cos(yaw), math.sin(yaw)
    rotation = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])  # forward, left, up
    return CameraView(position=np.array([0.0, 0.0, height]), rotation=rotation,
                      hfov_rad=1.04, vfov_rad=0.8, max_range_m=10.0)  # fmt: skip


def test_points_in_front_within_the_field_of_view_are_visible() -> None:
    view = _view()
    rows = view.points(np.array([[3.0, 0.5, 0.0], [-3.0, 0.0, 0.0], [3.0, 3.0, 0.0],
                                 [20.0, 0.0, 0.7]]))  # fmt: skip
    assert rows[:, 0].tolist() == [1.0, 0.0, 0.0, 0.0]
    assert np.allclose(rows[0, 1:], (3.0, 0.5, -0.7))


def test_turning_the_camera_turns_the_frame() -> None:
    rows = _view(yaw=math.pi / 2).points(np.array([[0.0, 3.0, 0.7]]))
    assert rows[0, 0] == 1.0 and np.allclose(rows[0, 1:], (3.0, 0.0, 0.0), atol=1e-9)


def test_segments_are_clipped_to_the_view() -> None:
    view = _view()
    seg = np.array([[[2.0, -10.0, 0.0], [2.0, 10.0, 0.0]], [[-1.0, 1.0, 0.0], [-2.0, 1.0, 0.0]]])
    rows = view.segments(seg)
    assert rows[1, 0] == 0.0
    assert rows[0, 0] == 1.0
    half = 2.0 * math.tan(0.52)
    assert np.allclose(sorted([rows[0, 2], rows[0, 5]]), [-half, half], atol=1e-6)


def test_field_model_counts() -> None:
    assert field_segments(KID_FIELD).shape == (LINE_COUNT, 2, 3)
    posts = goal_post_feet(KID_FIELD, 1.0)
    assert posts[0, 0] == KID_FIELD.half_length_m and posts[0, 1] > 0 and posts[2, 0] < 0


def test_noise_grows_with_distance_and_spares_invisible_rows() -> None:
    rows = np.array([[1.0, 1.0, 0.0, 0.0], [1.0, 8.0, 0.0, 0.0], [0.0, 0.0, 0.0, 0.0]])
    noisy = rows.copy()
    add_noise(noisy, slice(1, 4), 0.05, np.random.default_rng(1))
    assert np.all(noisy[2] == 0.0)
    near, far = (
        np.linalg.norm(noisy[0, 1:] - rows[0, 1:]),
        np.linalg.norm(noisy[1, 1:] - rows[1, 1:]),
    )
    assert 0 < near and 0 < far
