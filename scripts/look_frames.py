"""Writes the README's pictures of the league's look (``docs/look/*.png``).

``python scripts/look_frames.py [--out docs/look]``: red player 1 stands in front of the ball
facing the blue goal while a short replay is recorded, once per texture seed; ``hlvs render
REPLAY --camera red-1`` then writes what its head camera saw (the league's camera model of the
match seed: exposure and noise; the look's light with the main light's shadows), and the last
frame is kept as ``camera_seed_N.png``. The match video's overview camera of the first seed is
``overview.png``. Everything is procedural (:mod:`simulator.world.textures`): the pictures are
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
    names = ", ".join(f"camera_seed_{seed}.png" for seed in SEEDS)
    print(f"wrote {names} and overview.png to {args.out}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("LP_NUM_THREADS", "0")
    sys.exit(main(sys.argv[1:]))
