"""The built-in robots' jerseys: the team colour with the player number, found and read in an
opponent's camera image by a colour detector under the look's lights."""

from __future__ import annotations

import math

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from robot.motion import SERVO_PID, standing_posture
from simulator.replay.scene import scene_of
from simulator.scene_model import scene_model
from simulator.world import CameraRenderer, RobotPlacement, World
from simulator.world.textures import _DIGITS, jersey_tile, number_mask

RED1 = RobotId(TeamColor.RED, 1)
BLUE3 = RobotId(TeamColor.BLUE, 3)
BLUE2 = RobotId(TeamColor.BLUE, 2)


def test_every_number_is_drawn_and_distinct() -> None:
    masks = [number_mask(n, 64) for n in range(1, 13)]
    assert all(mask.mean() > 0.08 for mask in masks)
    assert len({mask.tobytes() for mask in masks}) == 12
    tile = jersey_tile(number=7, team_rgb=(0.1, 0.25, 0.9), size_px=64).astype(int)
    shirt = tile[~number_mask(7, 64)]
    assert (shirt[:, 2] > 2 * shirt[:, 0]).all()  # blue all over but for the number
    assert (tile[number_mask(7, 64)] == 217).all()  # white digits


def _scene(texture_seed: int) -> World:
    """Red 1 looking at blue 3 facing it (1 m ahead) and blue 2 turned away (its back)."""
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED1, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE3, model="kid-default", x_m=1.0, y_m=0.15, yaw_rad=math.pi),
            RobotPlacement(id=BLUE2, model="kid-default", x_m=1.3, y_m=-0.45, yaw_rad=0.0),
        ],
        seed=1,
        texture_seed=texture_seed,
    )
    posture = standing_posture()
    posture["Head"] = 0.05
    for robot in (RED1, BLUE3, BLUE2):
        for name in world.motor_names(robot):
            world.set_motor_pid(robot, name, *SERVO_PID)
    for _ in range(60):
        for robot in (RED1, BLUE3, BLUE2):
            for name, value in posture.items():
                world.set_motor_position(robot, name, value)
        world.step()
    return world


def _runs(indices: np.ndarray, gap: int) -> list[np.ndarray]:
    return np.split(indices, np.nonzero(np.diff(indices) > gap)[0] + 1) if indices.size else []


def _read_jerseys(image_bgr: np.ndarray) -> list[str]:
    """A team's blue-robot finder, left to right: columns of saturated blue at least 40 px tall
    (a shirt; thin blue boards behind the pitch are not), the rows of the largest block of them,
    and the digit drawn in what is not blue inside the shirt's outline, matched against the
    7 x 5 cells of the digits."""
    img = image_bgr.astype(int)
    b, g, r = img[..., 0], img[..., 1], img[..., 2]
    blue = (b > 2 * r) & (b > 2 * g) & (b >= 10)
    read = []
    for cols in _runs(np.nonzero(blue.sum(0) >= 40)[0], 5):
        x0, x1 = int(cols[0]), int(cols[-1]) + 1
        rows = max(_runs(np.nonzero(blue[:, x0:x1].mean(1) > 0.3)[0], 1), key=len)
        inside = blue[int(rows[0]) : int(rows[-1]) + 1, x0:x1]
        xx = np.arange(inside.shape[1])[None, :]
        left = np.where(inside.any(1), inside.argmax(1), inside.shape[1])[:, None]
        right = (inside.shape[1] - 1 - inside[:, ::-1].argmax(1))[:, None]
        digit = (xx > left) & (xx < right) & ~inside
        ys, xs = np.nonzero(digit)
        if ys.size == 0:
            read.append("?")
            continue
        box = digit[ys.min() : ys.max() + 1, xs.min() : xs.max() + 1]
        h, w = box.shape
        cells = np.array(
            [[box[h * i // 7 : h * (i + 1) // 7, w * j // 5 : w * (j + 1) // 5].mean()
              for j in range(5)] for i in range(7)]
        )  # fmt: skip
        read.append(
            min(
                _DIGITS,
                key=lambda d: np.abs(
                    cells - np.array([[int(c) for c in row] for row in _DIGITS[d]])
                ).sum(),
            )
        )
    return read


@pytest.mark.parametrize("texture_seed", [19, 1, 10, 7], ids=["day", "stadium", "chapel", "sunset"])
def test_an_opponent_finds_the_jerseys_and_reads_the_numbers(texture_seed: int) -> None:
    # Before, the robots were boxes in the team colour with a white chest plate: nothing to tell
    # one player from another. The stadium has blue boards behind the goal; the chapel hall is
    # dim (the shirt's blue some 20 grey levels); the sunset's light is orange.
    world = _scene(texture_seed)
    with CameraRenderer(world, 640, 480) as camera:
        image = np.frombuffer(camera.render(RED1), np.uint8).reshape(480, 640, 3)
    assert _read_jerseys(image) == ["3", "2"]  # blue 3's front, blue 2's back


def test_replays_show_the_jerseys() -> None:
    # hlvs render and the match video rebuild the scene from the replay: the shirts with their
    # numbers (the viewer draws them in the shirt's mean colour)
    world = _scene(19)
    scene = scene_of(world.model, tuple(world.placements), world.field, world.look)
    jerseys = [g for g in scene["geoms"] if "/visual:jersey_" in g["name"]]
    assert len(jerseys) == 6  # front and back of each robot
    for geom in jerseys:
        r, g, b, _ = geom["rgba"]
        assert (b > r) if geom["name"].startswith("blue") else (r > b)
    model = scene_model(scene)
    for name, number in (("jersey:blue_3", 3), ("jersey:red_1", 1)):
        texid = int(model.texture(name).id)
        adr, channels = int(model.tex_adr[texid]), int(model.tex_nchannel[texid])
        texels = model.tex_data[adr : adr + 64 * 64 * channels].reshape(64, 64, channels)
        white = texels[..., :3].min(-1) > 200
        assert (white == number_mask(number, 64)).all()
