"""The camera model's motion blur: a turning head smears the image along its motion."""

from __future__ import annotations

import numpy as np
import pytest

from simulator.world import CameraModel, CameraRenderer, World
from simulator.world.camera_model import blur_px_of, motion_blur

from .conftest import RED_1, eight_robots


def test_motion_blur_averages_shifted_copies() -> None:
    image = np.zeros((4, 12, 3), dtype=np.uint8)
    image[:, 4] = 200
    blurred = motion_blur(image, (3.0, 0.0))
    assert blurred[0, 4:8, 0].tolist() == [50, 50, 50, 50]  # spread over 4 columns
    assert motion_blur(image, (0.5, 0.2)) is image  # below a pixel: untouched


def test_image_motion_follows_the_turn() -> None:
    # 1 rad/s about the camera's up axis for 10 ms, 240 rows at 45 deg: about 2.9 columns
    dx, dy = blur_px_of(np.array([0.0, 1.0, 0.0]), height=240, fovy_deg=45.0, exposure_s=0.01)
    assert dx == pytest.approx(-120 / np.tan(np.radians(22.5)) * 0.01)
    assert dy == 0.0


def _frame(*, blur: bool, neck_rad_s: float) -> np.ndarray:
    model = CameraModel(noise_std=0.0, auto_exposure=1.0, motion_blur=blur, exposure_s=0.02)
    world = World.create(
        field_class="kid", robots=eight_robots()[:1], seed=1, camera_model=model
    )
    r = world.index.by_id[RED_1]
    neck = world.model.jnt_dofadr[world.model.actuator_trnid[r.actuators[r.motor_slot["Neck"]], 0]]
    world.data.qvel[neck] = neck_rad_s
    with CameraRenderer(world, 160, 120) as renderer:
        raw = renderer.render(RED_1)
    return np.frombuffer(raw, np.uint8).reshape(120, 160, 3).astype(int)


def test_a_turning_head_blurs_its_camera_image_when_asked() -> None:
    sharp = _frame(blur=False, neck_rad_s=6.0)
    blurred = _frame(blur=True, neck_rad_s=6.0)
    still = _frame(blur=True, neck_rad_s=0.0)
    assert np.array_equal(still, sharp)
    # horizontal detail is smoothed: neighbouring columns differ less
    def detail(image: np.ndarray) -> float:
        return float(np.abs(np.diff(image, axis=1)).mean())

    assert detail(blurred) < 0.8 * detail(sharp)
