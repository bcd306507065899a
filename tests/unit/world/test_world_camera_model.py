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


def _neck_dof(world: World) -> int:
    """The index in ``qvel`` of red player 1's neck joint."""
    r = world.index.by_id[RED_1]
    actuator = r.actuators[r.motor_slot["Neck"]]
    return int(world.model.jnt_dofadr[world.model.actuator_trnid[actuator, 0]])


def _frame(*, blur: bool, neck_rad_s: float) -> np.ndarray:
    model = CameraModel(noise_std=0.0, auto_exposure=1.0, motion_blur=blur, exposure_s=0.02)
    world = World.create(
        field_class="kid", robots=eight_robots()[:1], seed=1, camera_model=model
    )
    neck = _neck_dof(world)
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


@pytest.mark.parametrize(
    "model",
    [CameraModel.ideal(), CameraModel.league(7), CameraModel(seed=3, exposure_gain=1.0),
     CameraModel(seed=5, exposure_gain=1.3, noise_std=0.0, motion_blur=True)],
    ids=["ideal", "league", "noise-only", "gain-blur"],
)
@pytest.mark.parametrize("size", [(160, 120), (161, 121)], ids=["160x120", "161x121"])
def test_frames_read_in_camera_order_are_the_frames_turned(
    model: CameraModel, size: tuple[int, int]
) -> None:
    """The robot cameras read their frames from OpenGL in B,G,R order, bottom row first, and
    view them upside down: the same bytes as MuJoCo's R,G,B frame with its channels turned,
    whatever the camera model does to them and whatever the width (an odd one: rows unpadded)."""
    world = World.create(field_class="kid", robots=eight_robots()[:2], seed=2, camera_model=model)
    neck = _neck_dof(world)
    world.data.qvel[neck] = 4.0  # blur, where the model has it
    width, height = size
    with CameraRenderer(world, width, height) as renderer:
        assert renderer._read_bgr is not None  # noqa: SLF001 - the way under test
        read = renderer.render(RED_1, sim_time_ms=96)
        renderer._read_bgr = None  # noqa: SLF001 - MuJoCo's frame, turned
        turned = renderer.render(RED_1, sim_time_ms=96)
    assert len(read) == width * height * 3
    assert read == turned
    assert len(set(read)) > 20  # a picture, not a blank
