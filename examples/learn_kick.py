"""Learn a kick in hlvs/Kick-v0 with the cross-entropy method (numpy only).

The robot stands behind the ball (ball at x = 1 m, y = 0) and plays a keyframe kick with its
right foot (``robot.motion.KickMotion``) whose parameters are searched: where the robot stands
relative to the ball (``dx``, ``dy``), how far the foot winds up and strikes, how high, and how
fast. Every candidate is one seeded episode of ``--episode-s`` simulated seconds; its score is
the environment's ``kick_distance_m`` (how far the ball moved), and a fall scores zero. The
search starts from a deliberately weak guess and prints one JSON line: the kick distance of the
starting guess, of the final mean, the best seen, the wall time and the seed.

    python examples/learn_kick.py --seed 1
"""

from __future__ import annotations

import argparse
import json
import sys
import time

import gymnasium as gym
import numpy as np

import envs  # noqa: F401  (registers hlvs/Kick-v0)
from robot.motion import KickMotion, standing_posture
from robot.motion.kick import KickParams
from simulator.world import MOTOR_NAMES

BALL_X_M = 1.0
# name, starting guess (weak), lower and upper bound, starting spread
PARAMETERS = (
    ("dx_m", 0.20, 0.12, 0.40, 0.04),  # robot torso this far behind the ball
    ("dy_m", 0.05, -0.05, 0.15, 0.03),  # ... and this far to its left (kicks with the right foot)
    ("windup_x_m", -0.03, -0.12, 0.0, 0.03),
    ("strike_x_m", 0.08, 0.02, 0.20, 0.04),
    ("strike_lift_m", 0.02, 0.0, 0.06, 0.015),
    ("strike_s", 0.25, 0.08, 0.4, 0.06),
)
LOW = np.array([p[2] for p in PARAMETERS])
HIGH = np.array([p[3] for p in PARAMETERS])


def evaluate(env: gym.Env, theta: np.ndarray, *, seed: int, episode_s: float) -> float:  # type: ignore[type-arg]
    values = dict(zip((p[0] for p in PARAMETERS), theta.tolist(), strict=True))
    env.reset(
        seed=seed,
        options={
            "ball_x_m": BALL_X_M,
            "ball_y_m": 0.0,
            "robot_pose": (BALL_X_M - values["dx_m"], values["dy_m"], 0.0),
        },  # fmt: skip
    )
    stand = standing_posture("kid-default")
    kick = KickMotion(
        foot="right",
        start=stand,
        params=KickParams(windup_x_m=values["windup_x_m"], strike_x_m=values["strike_x_m"],
                          strike_lift_m=values["strike_lift_m"], strike_s=values["strike_s"]),
    )  # fmt: skip
    targets = dict(stand)
    info: dict[str, object] = {}
    for step in range(int(episode_s / 0.008)):
        t = step * 0.008
        if t >= 0.5 and not kick.done:  # settle into the stance, then kick
            targets.update(kick.step(0.008))
        action = np.array([targets.get(n, 0.0) for n in MOTOR_NAMES], dtype=np.float32)
        _, _, terminated, truncated, info = env.step(action)
        if terminated or truncated:
            break
    if info.get("fallen"):
        return 0.0
    return float(info.get("kick_distance_m", 0.0))


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1, help="seed of the search and episodes")
    parser.add_argument("--iterations", type=int, default=6, help="cross-entropy iterations")
    parser.add_argument("--population", type=int, default=12, help="candidates per iteration")
    parser.add_argument("--elite", type=int, default=3, help="candidates kept per iteration")
    parser.add_argument("--episode-s", type=float, default=3.0, help="simulated s per episode")
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    env = gym.make("hlvs/Kick-v0", max_episode_s=args.episode_s + 1.0)
    started = time.perf_counter()
    mean = np.array([p[1] for p in PARAMETERS])
    spread = np.array([p[4] for p in PARAMETERS])
    initial = evaluate(env, mean, seed=args.seed, episode_s=args.episode_s)
    best, best_theta = initial, mean.copy()
    history = []
    for iteration in range(args.iterations):
        population = np.clip(rng.normal(mean, spread, (args.population, len(mean))), LOW, HIGH)
        scores = np.array(
            [evaluate(env, theta, seed=args.seed, episode_s=args.episode_s) for theta in population]
        )
        elite = population[np.argsort(scores)[-args.elite :]]
        mean, spread = elite.mean(axis=0), elite.std(axis=0) + 0.002
        if scores.max() > best:
            best, best_theta = float(scores.max()), population[int(np.argmax(scores))]
        history.append(round(float(np.mean(np.sort(scores)[-args.elite :])), 3))
        print(f"iteration {iteration}: best {scores.max():.3f} m, elite mean {history[-1]} m",
              file=sys.stderr)  # fmt: skip
    final = evaluate(env, mean, seed=args.seed, episode_s=args.episode_s)
    env.close()
    print(json.dumps({
        "example": "learn_kick", "seed": args.seed,
        "initial_kick_m": round(initial, 3), "final_mean_kick_m": round(final, 3),
        "best_kick_m": round(best, 3), "elite_mean_per_iteration_m": history,
        "episodes": 2 + args.iterations * args.population,
        "wall_s": round(time.perf_counter() - started, 1),
        "best_parameters": dict(zip((p[0] for p in PARAMETERS),
                                    [round(v, 3) for v in best_theta.tolist()], strict=True)),
    }))  # fmt: skip
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
