"""The PPO example trains a few thousand steps (the loop, the logs, the checkpoints, the policy
file, the plot), and the robot image built from its policy file loads it in the stub (real
Docker engine, the project's stub image). It checks that the pieces work, not that it learned."""

from __future__ import annotations

import csv
import json
import os
import subprocess
import sys
from pathlib import Path

import docker
import numpy as np
import pytest

from robot.learned import load_policy
from simulator.world import MOTOR_NAMES

ROOT = Path(__file__).resolve().parents[3]


@pytest.fixture(scope="module")
def trained(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, dict[str, object]]:
    out = tmp_path_factory.mktemp("stand_kick")
    run = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "learn_stand_kick.py"), "--seed", "3",
         "--env-steps", "3000", "--envs", "4", "--rollouts", "16", "--progress-s", "0",
         "--eval-episodes", "2", "--out", str(out)],
        capture_output=True, text=True, timeout=300, cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )  # fmt: skip
    assert run.returncode == 0, run.stderr[-3000:]
    assert "steps " in run.stdout and "episodes" in run.stdout  # progress lines
    # the default device is one the machine has: no "Invalid device specification (cuda:0)"
    assert "Invalid device" not in run.stderr, run.stderr[-2000:]
    return out, json.loads(run.stdout.strip().splitlines()[-1])


def test_a_short_run_touches_and_moves_the_ball(
    trained: tuple[Path, dict[str, object]],
) -> None:
    """The shaped reward's contact signal shows from the first episodes (the curriculum starts
    the ball 3 cm nearer the toe), and touched balls move."""
    out, summary = trained
    with (out / "episodes.csv").open() as f:
        rows = list(csv.DictReader(f))
    touched = [r for r in rows if r["touched"] == "1"]
    assert len(touched) >= len(rows) // 4, f"{len(touched)} of {len(rows)} episodes touched"
    assert float(rows[0]["ball_closer_m"]) == 0.03  # the first episodes start at 3 cm
    assert float(rows[-1]["ball_closer_m"]) == 0.0  # the ball where the skill finds it
    moved = [float(r["kick_distance_m"]) for r in touched]
    assert max(moved) > 0.1 and float(np.mean(moved)) > 0.02
    # the ball lies still until the robot touches it; a robot falling onto it may push it a
    # little more slowly than a touch (0.1 m/s)
    untouched = [(float(r["kick_distance_m"]), r["fallen"] == "1") for r in rows
                 if r["touched"] == "0"]  # fmt: skip
    assert all(d < (0.1 if fell else 0.05) for d, fell in untouched), untouched
    first = summary["training"]["first"]  # type: ignore[index]
    share = sum(r["touched"] == "1" for r in rows[:200]) / len(rows[:200])
    assert first["touched_share"] == pytest.approx(share, abs=0.001)


def test_training_writes_logs_checkpoints_policy_and_plot(
    trained: tuple[Path, dict[str, object]],
) -> None:
    out, summary = trained
    assert summary["env_steps"] == 3000  # 750 steps of the vector of 4
    with (out / "episodes.csv").open() as f:
        rows = list(csv.DictReader(f))
    assert rows and int(rows[-1]["env_steps"]) <= 3000
    assert [int(r["episode"]) for r in rows] == list(range(1, len(rows) + 1))
    penalties = [float(r["fall_penalty"]) for r in rows]  # 1, rising to 3 at 80 % of the steps
    assert penalties[0] == 1.0 and max(penalties) == 3.0 and penalties == sorted(penalties)
    # the exploration as learnt (log std -1.2 at first), capped from 40 % of the steps: the cap
    # falls to -2.5 at 80 %, and the policy's log std is under it from then on
    log_std = [(int(r["env_steps"]), float(r["log_std"])) for r in rows]
    assert log_std[0][1] == pytest.approx(-1.2, abs=0.05)
    for steps, value in log_std:
        cap = -1.2 - 1.3 * min(max((steps / 3000 - 0.4) / 0.4, 0.0), 1.0)
        assert value <= cap + 0.002, (steps, value, cap)
    assert [v for s, v in log_std if s >= 2400] and all(
        v <= -2.499 for s, v in log_std if s >= 2400
    )
    # a fall costs 3 at most, standing still 0.47, the toe going 1 m from the ball 1
    assert all(float(r["return"]) >= -4.5 for r in rows)
    runs = out / "skrl" / "ppo"
    assert list(runs.glob("events.out.tfevents.*")), "no TensorBoard events"
    assert list((runs / "checkpoints").glob("*.pickle")), "no skrl checkpoints"
    policy = load_policy(out / "policy.npz")
    assert policy.motors == MOTOR_NAMES and len(policy.layers) == 3
    # the inputs' running standardisation is folded into the file's first layer: the robot's
    # numpy runner gives the trained network's mean actions
    assert summary["obs_norm"] is True
    assert summary["export_max_error"] < 1e-4, summary["export_max_error"]
    assert (out / "learning_curve.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    learned, random = summary["learned"], summary["random"]
    assert isinstance(learned, dict) and isinstance(random, dict)
    assert learned["episodes"] == random["episodes"] == 2


@pytest.mark.docker
def test_the_policy_image_plays_the_learned_kick_in_the_stub(
    trained: tuple[Path, dict[str, object]], docker_client: docker.DockerClient
) -> None:
    out, _ = trained
    build = subprocess.run(
        [sys.executable, str(ROOT / "examples" / "stand_kick_image.py"), str(out / "policy.npz")],
        capture_output=True, text=True, timeout=600, cwd=ROOT,
        env={**os.environ, "PYTHONPATH": str(ROOT)},
    )  # fmt: skip
    assert build.returncode == 0, build.stderr[-3000:]
    tag = build.stdout.strip().splitlines()[-1]
    assert tag.startswith("hlvs-runner/stand-kick:")
    # the stub in the image finds the policy by itself ($HLVS_KICK_POLICY) and plays it
    script = (
        "from robot.stub.options import parse_args\n"
        "from robot.stub.runner import _kick_policy\n"
        "from robot.stub.controller import StubController\n"
        "from robot.stub.behaviour import Role\n"
        "from contracts.geometry import Pose\n"
        "from robot.learned import PolicyMotion\n"
        "p = _kick_policy(parse_args(['striker']))\n"
        "c = StubController(role=Role.STRIKER, start_pose=Pose(x_m=0, y_m=0, yaw_rad=0),\n"
        "                   kick_policy=p)\n"
        "m = PolicyMotion(p)\n"
        "m.sense(dict(zip(p.motors, p.stance)), (0.0, 0.0, 9.81), (0.0, 0.0, 0.0))\n"
        "t = m.step(0.008)\n"
        "print(p.skill, c.field.kick_feet, len(t))\n"
    )
    try:
        printed = docker_client.containers.run(
            tag, entrypoint=["python", "-c", script], remove=True, network_mode="none"
        )
        assert printed.decode().split() == ["stand-kick-right", "('right',)", "20"]
    finally:
        docker_client.images.remove(tag, noprune=False)
