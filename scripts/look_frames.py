"""Writes the README's pictures of the league's look (``docs/look/*.png``).

``python scripts/look_frames.py [--out docs/look]``: red player 1 stands in front of the ball
facing the blue goal; its head camera's frame is written with the league's camera model
(exposure and noise of the match seed) for two texture seeds and in the ideal mode, with the
match video's overview camera. Everything is procedural (:mod:`simulator.world.textures`): the
pictures are this script's output, nothing else.
"""

from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=REPO / "docs" / "look")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO))
    from simulator.gl import choose_offscreen_gl

    choose_offscreen_gl()
    import mujoco
    import numpy as np

    from contracts.ids import RobotId, TeamColor
    from referee.snapshot import PlaceBall
    from robot.motion import standing_posture
    from simulator.png import write_png
    from simulator.world import CameraRenderer, RobotPlacement, World
    from simulator.world.camera_model import CameraModel
    from simulator.world.look import apply_luminosity

    red1 = RobotId(TeamColor.RED, 1)
    placements = [
        RobotPlacement(id=red1, model="kid-default", x_m=1.6, y_m=0.5, yaw_rad=-0.12),
        RobotPlacement(
            id=RobotId(TeamColor.BLUE, 1), model="kid-default", x_m=3.9, y_m=-0.3, yaw_rad=3.0
        ),
    ]
    args.out.mkdir(parents=True, exist_ok=True)
    shots = (
        ("league", 1, CameraModel.league(7)),
        ("league_seed_7", 7, CameraModel.league(7)),
        ("ideal", 1, CameraModel.ideal()),
    )
    for name, texture_seed, camera in shots:
        world = World.create(
            field_class="kid", robots=placements, seed=7, texture_seed=texture_seed,
            camera_model=camera,
        )  # fmt: skip
        world.apply(PlaceBall(position=(2.5, 0.38, 0.07), velocity=(0.0, 0.0, 0.0)))
        posture = standing_posture()
        posture["Head"] = 0.1
        for _ in range(60):
            for robot in world.robot_ids:
                world.set_motor_positions(robot, list(posture), list(posture.values()))
            world.step()
        with CameraRenderer(world, 320, 240) as renderer:
            bgr = renderer.render(red1, sim_time_ms=world.sim_time_ms)
        rgb = np.frombuffer(bgr, np.uint8).reshape(240, 320, 3)[:, :, ::-1]
        write_png(args.out / f"camera_{name}.png", np.ascontiguousarray(rgb))
        if name == "ideal":
            with mujoco.Renderer(world.model, 270, 480) as overview:
                overview.update_scene(world.data, camera="overview")
                write_png(
                    args.out / "overview.png",
                    apply_luminosity(overview.render(), world.look.luminosity),
                )
    print(f"wrote {', '.join(f'camera_{name}.png' for name, *_ in shots)} and overview.png "
          f"to {args.out}")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("LP_NUM_THREADS", "0")
    sys.exit(main(sys.argv[1:]))
