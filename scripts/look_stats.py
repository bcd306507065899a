"""Per-look statistics of what a robot's camera sees (the README's figure page).

``python scripts/look_stats.py [--seeds 1-20] [--json]``: red player 1 stands in front of the ball
facing the blue goal (the scene of ``scripts/look_frames.py``), and its head camera (320x240,
the league's camera model of match seed 7) renders one frame per ``texture_seed``, once with the
ball and once without it. Per seed: the background and luminosity the seed picks, the frame's
mean brightness (0-255), the turf's mean colour and hue spread (pixels below the horizon
that change neither with the ball nor are line-bright: hue's standard deviation in degrees) and
the ball's contrast (its pixels' mean brightness over the turf's round it, and the spread of
its brightness: the 90th over the 10th percentile; ``ball_px`` its size in pixels). Then the
range over the seeds. One JSON document with ``--json``, else a table.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def _seeds(text: str) -> list[int]:
    first, _, last = text.partition("-")
    return list(range(int(first), int(last or first) + 1))


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=_seeds, default=_seeds("1-20"), help="e.g. 1-20")
    parser.add_argument("--json", action="store_true", help="print one JSON document")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(REPO))
    from simulator.gl import choose_offscreen_gl

    choose_offscreen_gl()
    import mujoco
    import numpy as np
    from look_frames import scene

    from contracts.ids import RobotId, TeamColor
    from referee.snapshot import PlaceBall
    from robot.motion import standing_posture
    from simulator.world import CameraRenderer
    from simulator.world.look import BACKGROUNDS

    red1 = RobotId(TeamColor.RED, 1)
    rows = []
    for seed in args.seeds:
        world = scene(seed)
        posture = standing_posture()
        posture["Head"] = 0.35
        for _ in range(60):
            for robot in world.robot_ids:
                world.set_motor_positions(robot, list(posture), list(posture.values()))
            world.step()
        frames = []
        with CameraRenderer(world, 320, 240) as camera:
            for ball in ((2.4, 0.25), (50.0, 50.0)):
                world.apply(PlaceBall(position=(*ball, 0.07), velocity=(0.0, 0.0, 0.0)))
                mujoco.mj_forward(world.model, world.data)
                raw = camera.render(red1)
                frames.append(np.frombuffer(raw, np.uint8).reshape(240, 320, 3)[..., ::-1])
        with_ball, empty = (f.astype(np.float64) for f in frames)
        ball = np.abs(with_ball - empty).max(-1) > 12
        value = empty.max(-1)
        lower = np.zeros(ball.shape, np.bool_)
        lower[150:] = True  # well below the horizon: turf and lines
        turf = lower & ~ball & (empty[..., 1] >= empty[..., 0]) & (empty[..., 1] >= empty[..., 2])
        turf &= value < np.percentile(value[lower], 85)  # not the lines
        r, g, b = (empty[..., k][turf] for k in range(3))
        hue = np.degrees(np.arctan2(math.sqrt(3.0) * (g - b), 2.0 * r - g - b))
        ys, xs = np.nonzero(ball)
        around = np.zeros(ball.shape, np.bool_)
        around[max(ys.min() - 8, 0) : ys.max() + 9, max(xs.min() - 8, 0) : xs.max() + 9] = True
        ball_values = with_ball.max(-1)[ball]
        look = world.look
        rows.append({
            "texture_seed": seed,
            "background": BACKGROUNDS[look.background].league_name,
            "luminosity": round(look.luminosity, 3),
            "mean_brightness": round(float(with_ball.mean()), 1),
            "turf_rgb": [round(float(c.mean())) for c in (r, g, b)],
            "turf_hue_std_deg": round(float(hue.std()), 1),
            "ball_px": int(ball.sum()),
            "ball_contrast": round(float(ball_values.mean() / value[around & turf].mean()), 2),
            "ball_spread": round(float(np.percentile(ball_values, 90)
                                       / max(np.percentile(ball_values, 10), 1.0)), 2),
        })  # fmt: skip
    summary = {
        key: [min(row[key] for row in rows), max(row[key] for row in rows)]
        for key in ("mean_brightness", "turf_hue_std_deg", "ball_contrast", "ball_spread")
    }
    if args.json:
        print(json.dumps({"seeds": rows, "range": summary}))
        return 0
    for row in rows:
        print(" ".join(f"{k}={v}" for k, v in row.items()))
    print("range:", json.dumps(summary))
    return 0


if __name__ == "__main__":
    os.environ.setdefault("LP_NUM_THREADS", "0")
    sys.exit(main(sys.argv[1:]))
