"""Team models wear the team's jersey with the player number where their manifest says
(``jersey``: plates on a link), as the league's robots do: an opponent's colour finder finds the
shirts of two Wolfgangs and reads their numbers; the replay keeps them; a manifest that places
them badly is refused with the field and the expected value."""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from robot.motion import SERVO_PID, standing_posture
from simulator.errors import ModelError
from simulator.replay.scene import scene_of
from simulator.scene_model import scene_model
from simulator.world import CameraRenderer, RobotPlacement, World
from simulator.world.robots.team import load_team_model
from simulator.world.robots.team.manifest import load_manifest
from simulator.world.textures import _DIGITS, number_mask
from tests.unit.models.conftest import WOLFGANG, edit_manifest

RED1 = RobotId(TeamColor.RED, 1)
BLUE3 = RobotId(TeamColor.BLUE, 3)
BLUE2 = RobotId(TeamColor.BLUE, 2)


def _scene(wolfgang: Path, texture_seed: int) -> World:
    """Red 1 (built-in) looking at Wolfgang blue 3 facing it and Wolfgang blue 2 turned away."""
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED1, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE3, model=str(wolfgang), x_m=1.2, y_m=0.2, yaw_rad=math.pi),
            RobotPlacement(id=BLUE2, model=str(wolfgang), x_m=1.5, y_m=-0.5, yaw_rad=0.0),
        ],
        seed=1,
        texture_seed=texture_seed,
    )
    posture = standing_posture()
    posture["Head"] = 0.05
    for name in world.motor_names(RED1):
        world.set_motor_pid(RED1, name, *SERVO_PID)
    for _ in range(60):
        for name, value in posture.items():
            world.set_motor_position(RED1, name, value)
        world.step()
    return world


def _red1_image(world: World) -> np.ndarray:
    with CameraRenderer(world, 640, 480) as camera:
        return np.frombuffer(camera.render(RED1), np.uint8).reshape(480, 640, 3)


def _near(mask: np.ndarray, reach: int) -> np.ndarray:
    """Pixels with a ``mask`` pixel at most ``reach`` away to the left, right, above and below."""

    def after(m: np.ndarray) -> np.ndarray:  # a mask pixel at most reach before, along a row
        at = np.arange(m.shape[1])[None, :]
        return at - np.maximum.accumulate(np.where(m, at, -(10**6)), axis=1) <= reach

    return (
        after(mask) & after(mask[:, ::-1])[:, ::-1]
        & after(mask.T).T & after(mask.T[:, ::-1])[:, ::-1].T
    )  # fmt: skip


def _components(mask: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The 4-connected regions of ``mask``: rows and columns of each."""
    seen = np.zeros(mask.shape, np.bool_)
    found = []
    for start in zip(*np.nonzero(mask), strict=True):
        if seen[start]:
            continue
        seen[start] = True
        stack, pixels = [start], []
        while stack:
            y, x = stack.pop()
            pixels.append((y, x))
            for yy, xx in ((y + 1, x), (y - 1, x), (y, x + 1), (y, x - 1)):
                inside = 0 <= yy < mask.shape[0] and 0 <= xx < mask.shape[1]
                if inside and mask[yy, xx] and not seen[yy, xx]:
                    seen[yy, xx] = True
                    stack.append((yy, xx))
        ys, xs = np.array(pixels).T
        found.append((ys, xs))
    return found


def _read_jerseys(image_bgr: np.ndarray) -> list[str]:
    """A team's blue-shirt reader, left to right: what is not saturated blue but has blue
    within 40 px on all four sides (a number inside a shirt), regions of at least 200 px (the
    numbers here are some 700; gaps between a mesh's parts are smaller) about as tall as a
    digit is for its width, matched against the 7 x 5 cells of the digits."""
    img = image_bgr.astype(int)
    b, g, r = img[..., 0], img[..., 1], img[..., 2]
    blue = (b > 2 * r) & (b > 2 * g) & (b >= 10)
    read = []
    for ys, xs in _components(~blue & _near(blue, 40)):
        h, w = int(np.ptp(ys)) + 1, int(np.ptp(xs)) + 1
        if len(ys) < 200 or not 1.0 <= h / w <= 3.0:
            continue
        box = np.zeros((h, w), np.bool_)
        box[ys - ys.min(), xs - xs.min()] = True
        cells = np.array(
            [[box[h * i // 7 : h * (i + 1) // 7, w * j // 5 : w * (j + 1) // 5].mean()
              for j in range(5)] for i in range(7)]
        )  # fmt: skip
        digit = min(
            _DIGITS,
            key=lambda d: np.abs(
                cells - np.array([[int(c) for c in row] for row in _DIGITS[d]])
            ).sum(),
        )
        read.append((int(xs.min()), digit))
    return [digit for _, digit in sorted(read)]


@pytest.mark.parametrize("texture_seed", [19, 10], ids=["day", "chapel"])
def test_an_opponent_reads_the_numbers_on_team_models(texture_seed: int) -> None:
    # the example Wolfgang's manifest places a plate on the front and one on the back of its
    # torso link; before, a team model wore no number (its trunk in the team colour only)
    assert _read_jerseys(_red1_image(_scene(WOLFGANG, texture_seed))) == ["3", "2"]


def test_without_the_field_a_team_model_wears_no_jersey(wolfgang_copy: Path) -> None:
    manifest = json.loads((wolfgang_copy / "robot_model.json").read_text())
    del manifest["jersey"]
    (wolfgang_copy / "robot_model.json").write_text(json.dumps(manifest))
    world = _scene(wolfgang_copy, 19)
    names = [world.model.geom(i).name for i in range(world.model.ngeom)]
    assert [n for n in names if "/visual:jersey_" in n] == [
        "red_1/visual:jersey_front", "red_1/visual:jersey_back",
    ]  # fmt: skip
    assert "3" not in _read_jerseys(_red1_image(world))


def test_replays_keep_the_team_models_jerseys() -> None:
    world = _scene(WOLFGANG, 19)
    scene = scene_of(world.model, tuple(world.placements), world.field, world.look)
    plates = sorted(g["name"] for g in scene["geoms"] if "/visual:jersey_" in g["name"])
    assert plates == [
        f"{robot}/visual:jersey_{side}"
        for robot in ("blue_2", "blue_3", "red_1") for side in ("back", "front")
    ]  # fmt: skip
    model = scene_model(scene)
    texid = int(model.texture("jersey:blue_3").id)
    adr, channels = int(model.tex_adr[texid]), int(model.tex_nchannel[texid])
    texels = model.tex_data[adr : adr + 64 * 64 * channels].reshape(64, 64, channels)
    assert ((texels[..., :3].min(-1) > 200) == number_mask(3, 64)).all()


PLATE = {"pos_m": [0.1, 0.0, 0.15], "size_m": [0.12, 0.12]}


@pytest.mark.parametrize(
    ("jersey", "pointer", "words"),
    [
        ({"link": "torso"}, "/jersey", "expected front, back or both"),
        (
            {"link": "torso", "front": {**PLATE, "size_m": [0.12, 0]}},
            "/jersey/front/size_m",
            "each above 0 and at most 0.5",
        ),
        (
            {"link": "torso", "back": {**PLATE, "pos_m": [0.1, 0.0]}},
            "/jersey/back/pos_m",
            "is not [x, y, z] in metres",
        ),
        (
            {"link": "torso", "front": {**PLATE, "colour": "red"}},
            "/jersey/front/colour",
            "known fields: pos_m, size_m",
        ),
        ({"link": "torso", "side": PLATE}, "/jersey/side", "known fields: back, front, link"),
    ],
)
def test_a_badly_placed_jersey_is_refused_naming_the_field(
    wolfgang_copy: Path, jersey: dict[str, Any], pointer: str, words: str
) -> None:
    edit_manifest(wolfgang_copy, jersey=jersey)
    with pytest.raises(ModelError) as caught:
        load_manifest(wolfgang_copy)
    problems = [(p.where, p.reason) for p in caught.value.problems]
    assert any(where == pointer and words in reason for where, reason in problems), problems


def test_a_jersey_on_a_link_the_model_lacks_is_refused(wolfgang_copy: Path) -> None:
    edit_manifest(wolfgang_copy, jersey={"link": "torso_link", "front": PLATE})
    with pytest.raises(ModelError) as caught:
        load_team_model(wolfgang_copy)
    problems = [(p.where, p.reason) for p in caught.value.problems]
    assert ("/jersey/link", "no link 'torso_link' in the model; did you mean 'torso'?") in problems
