"""Writes the README's pictures of the league's look (``docs/look/*.png``).

``python scripts/look_frames.py [--out docs/look]``: red player 1 stands in front of the ball
facing the blue goal while a short replay is recorded, once per texture seed; ``hlvs render
REPLAY --camera red-1`` then writes what its head camera saw (the league's camera model of the
match seed: exposure and noise; the look's light with the main light's shadows), and the last
frame is kept as ``camera_seed_N.png``. The match video's overview camera of the first seed is
``overview.png``. ``camera_team_models.png``: red player 1's head camera (the same camera model,
the main light's shadows on) facing two blue team models, the example Wolfgang (its meshes and
the jersey its manifest places), number 3 facing it and number 2 turned away, in the look of
``texture_seed`` 19; rendered from the world (a replay keeps a team model's meshes as their
bounding boxes). Everything is procedural (:mod:`simulator.world.textures`): the pictures are
this script's output, nothing else.
"""

from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
SEEDS = (19, 16, 9)  # a bright day, the pink dawn, the dim chapel hall


def scene(texture_seed: int) -> Any:
    """The README frames' world of ``texture_seed`` (match seed 7, the league's camera model):
    red player 1 at (1.6, 0.5) facing the blue goal, blue player 1 at (3.9, -0.3) facing it.
    Call after :func:`simulator.gl.choose_offscreen_gl`."""
    from contracts.ids import RobotId, TeamColor
    from simulator.world import RobotPlacement, World
    from simulator.world.camera_model import CameraModel

    placements = [
        RobotPlacement(
            id=RobotId(TeamColor.RED, 1), model="kid-default", x_m=1.6, y_m=0.5, yaw_rad=-0.12
        ),
        RobotPlacement(
            id=RobotId(TeamColor.BLUE, 1), model="kid-default", x_m=3.9, y_m=-0.3, yaw_rad=3.0
        ),
    ]
    return World.create(
        field_class="kid", robots=placements, seed=7, texture_seed=texture_seed,
        camera_model=CameraModel.league(7),
    )  # fmt: skip


def team_models_frame(path: Path) -> None:
    """Writes ``camera_team_models.png`` (see the module's docstring) to ``path``. Call after
    :func:`simulator.gl.choose_offscreen_gl`."""
    import math

    import numpy as np

    from contracts.ids import RobotId, TeamColor
    from robot.motion import standing_posture
    from simulator.png import write_png
    from simulator.world import CameraRenderer, RobotPlacement, World
    from simulator.world.camera import SHADOWS_ENV
    from simulator.world.camera_model import CameraModel
    from simulator.world.robots import robot_model

    wolfgang = str(REPO / "configs" / "examples" / "robots" / "wolfgang")
    red1 = RobotId(TeamColor.RED, 1)
    placements = [
        RobotPlacement(id=red1, model="kid-default", x_m=0.0, y_m=0.0, yaw_rad=0.0),
        RobotPlacement(
            id=RobotId(TeamColor.BLUE, 3), model=wolfgang, x_m=1.1, y_m=0.25, yaw_rad=math.pi
        ),
        RobotPlacement(
            id=RobotId(TeamColor.BLUE, 2), model=wolfgang, x_m=1.4, y_m=-0.45, yaw_rad=-0.3
        ),
    ]
    world = World.create(
        field_class="kid", robots=placements, seed=7, texture_seed=SEEDS[0],
        camera_model=CameraModel.league(7),
    )  # fmt: skip
    posture = standing_posture()
    posture["Head"] = 0.05
    stand = robot_model(wolfgang)
    for _ in range(60):
        world.set_motor_positions(red1, list(posture), list(posture.values()))
        for robot in world.robot_ids[1:]:
            world.set_motor_positions(
                robot, [m.name for m in stand.motors], list(stand.standing_pose_rad)
            )
        world.step()
    os.environ[SHADOWS_ENV] = "map"  # as hlvs render --camera draws the other frames
    with CameraRenderer(world, 320, 240) as camera:
        bgr = np.frombuffer(camera.render(red1), np.uint8).reshape(240, 320, 3)
    write_png(path, np.ascontiguousarray(bgr[..., ::-1]))


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "look")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO))
    from simulator.gl import choose_offscreen_gl

    choose_offscreen_gl()
    import mujoco

    from referee.snapshot import PlaceBall
    from robot.motion import standing_posture
    from simulator.png import write_png
    from simulator.recorder import Recorder

    args.out.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=str(REPO))
    with tempfile.TemporaryDirectory() as tmp:
        for texture_seed in SEEDS:
            world = scene(texture_seed)
            world.apply(PlaceBall(position=(2.8, 0.3, 0.07), velocity=(0.0, 0.0, 0.0)))
            posture = standing_posture()
            posture["Head"] = 0.1
            replay = Path(tmp) / f"seed_{texture_seed}.hlvsrec"
            with Recorder(replay, world, match_id=f"look-{texture_seed}", rate_hz=5.0) as rec:
                for _ in range(60):
                    for robot in world.robot_ids:
                        world.set_motor_positions(robot, list(posture), list(posture.values()))
                    world.step()
                    rec.record(world, {"state": "PLAYING"})
            frames = Path(tmp) / f"frames_{texture_seed}"
            subprocess.run(
                [sys.executable, "-m", "hlvs", "render", str(replay), "--camera", "red-1",
                 "-o", str(frames), "--fps", "5"],
                check=True, env=env, cwd=REPO,
            )  # fmt: skip
            last = sorted(frames.glob("red-1_*.png"))[-1]
            shutil.copyfile(last, args.out / f"camera_seed_{texture_seed}.png")
            if texture_seed == SEEDS[0]:
                with mujoco.Renderer(world.model, 270, 480) as overview:
                    overview.update_scene(world.data, camera="overview")
                    write_png(args.out / "overview.png", overview.render())
    team_models_frame(args.out / "camera_team_models.png")
    names = ", ".join(f"camera_seed_{seed}.png" for seed in SEEDS)
    print(f"wrote {names}, overview.png and camera_team_models.png to {args.out}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("LP_NUM_THREADS", "0")
    sys.exit(main(sys.argv[1:]))
