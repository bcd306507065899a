"""Learn to kick the ball towards the goal from a stand (hlvs/StandKick-v0) with PPO.

PPO is skrl's (JAX on the CPU; ``pip install '.[learn]'``), over the project's vectorised
environment (``envs.vector.make_vector``: in this process, or ``--remotes N`` simulator
containers). The policy moves the robot's 12 leg motors around the walking stance (the
kicking leg's hip and knee pitch by up to 1 rad, the other joints less; arms and head stay), one
decision per 32 ms, from what the robot API reports: joint angles, accelerometer, gyro and the
time since the skill started (no ball or robot position), each input standardised by its
running mean and standard deviation (``--obs-norm``, folded into the first layer of the policy
file). It writes to ``--out``:

- ``episodes.csv``: one row per finished episode (environment steps so far, return, kick
  distance, fastest ball speed, fallen, touched the ball, the fall penalty, the curriculum's
  ball offset and the policy's mean log standard deviation then), and progress lines on the
  terminal;
- ``skrl/``: skrl's TensorBoard event files and checkpoints;
- ``policy.npz``: the policy's weights for the robot (:mod:`robot.learned`; numpy only), written
  at every progress line and at the end;
- ``learning_curve.png``: the return per episode over training against a random policy, and
  the kick distance, the share of fast balls (>= 1 m/s) and of falls;
- ``summary.json``: the training episodes' figures over the first and the last 200 (ball
  travel, return, shares touched, fast, fallen), the evaluation of the learned policy (the
  ``policy.npz`` run by the robot's own code, deterministic) and of a random policy on the same
  seeded episodes.

The reward is the environment's shaped one (:mod:`envs.stand_kick`: the toe's approach to the
ball, a bonus for the first touch, the ball's progress towards the goal, a cost for standing
still and for a fall); a fall costs 1 until 40 % of the steps, then more, up to 3 from 80 % on
(``--fall-penalty``, ``--fall-penalty-end``). A curriculum starts the ball 3 cm nearer the toe
and moves it back to where the skill finds it over the first 30 % of the steps
(``--curriculum-m``, ``--curriculum-until``): first touch the ball at all, then reach it, then
kick without falling. The policy's exploration (the log standard deviation of its actions,
learnt by PPO from ``--init-log-std``) is capped from 40 % of the steps, the cap falling to
``--final-log-std`` at 80 %: the last episodes it learns from are nearly the kick it will play,
not the same kick shaken into a fall.

``--class adult`` trains adult-default on the adult pitch with its ball (``robot_class`` of the
environment); the inputs, actions and their scales are the kid's.

    python examples/learn_stand_kick.py --seed 1 --out runs/stand_kick
    python examples/learn_stand_kick.py --class adult --seed 1 --out runs/stand_kick_adult
    python examples/learn_stand_kick.py --plot-runs runs/s1 runs/s2 runs/s3 --out seeds.png
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import os
import sys
import time
from collections import deque
from pathlib import Path
from typing import Any

os.environ.setdefault("JAX_PLATFORMS", "cpu")

import gymnasium as gym  # noqa: E402
import numpy as np  # noqa: E402

import envs  # noqa: E402,F401  (registers hlvs/StandKick-v0)
from envs.vector import make_vector  # noqa: E402
from robot.learned import Policy, PolicyMotion, load_policy, save_policy  # noqa: E402
from simulator.world import MOTOR_NAMES  # noqa: E402

ENV_ID = "hlvs/StandKick-v0"
STEPS_PER_ACTION = 4  # 32 ms per decision
EPISODE_S = 1.5
HIDDEN = (64, 64)
OBS_NORM_EPSILON = 0.01  # inputs that hardly vary (the arms' joints) are not blown up to noise
# network input scale: joints (rad) as they are, accelerometer / 10, gyro / 4, time / episode
OBS_SCALE = np.array([1.0] * 20 + [0.1] * 3 + [0.25] * 3 + [1.0 / EPISODE_S])
# how far (rad) the policy may move each motor from the stance: the kicking (right) leg's hip
# and knee pitch most (a kick draws the foot back and swings it through, about 0.9 rad each),
# its ankle and the standing leg's pitch joints less, the roll and yaw joints least; arms and
# head stay still
JOINT_SCALES = {"LegUpperR": 1.0, "LegLowerR": 1.0, "AnkleR": 0.5, "LegUpper": 0.4,
                "LegLower": 0.4, "Ankle": 0.4, "Pelv": 0.2, "Foot": 0.2, "PelvY": 0.1}  # fmt: skip
ACTION_SCALE = np.array(
    [next((v for k, v in sorted(JOINT_SCALES.items(), key=lambda kv: -len(kv[0]))
           if name.startswith(k)), 0.0) for name in MOTOR_NAMES]
)  # fmt: skip


def flat_observation(obs: dict[str, Any]) -> np.ndarray:
    """The policy's input, batched: joints, accelerometer, gyro, time (no force sensors)."""
    parts = (obs["joints"], obs["accelerometer"], obs["gyro"], obs["time"])
    return np.concatenate([np.asarray(p, np.float32) for p in parts], axis=-1)


def policy_template(robot_class: str = "kid") -> Policy:
    """The mapping of actions to motor targets, without weights (filled in by export)."""
    env = gym.make(ENV_ID, robot_class=robot_class).unwrapped
    space = env.action_space
    assert isinstance(space, gym.spaces.Box)
    stance = np.asarray(env.stance, np.float64)  # type: ignore[attr-defined]
    env.close()
    return Policy(
        skill="stand-kick-right", motors=MOTOR_NAMES, layers=(), obs_scale=OBS_SCALE,
        stance=stance, action_scale=ACTION_SCALE, low=space.low.astype(np.float64),
        high=space.high.astype(np.float64), control_period_ms=8 * STEPS_PER_ACTION,
        duration_s=EPISODE_S,
    )  # fmt: skip


def _ramp(share: float, span: tuple[float, float]) -> float:
    """0 until ``span[0]`` of the steps, 1 from ``span[1]`` on, linear between."""
    return min(max((share - span[0]) / max(span[1] - span[0], 1e-9), 0.0), 1.0)


class _Schedule:
    """A value over training: ``start`` until ``span[0]`` of the steps, then linearly to ``end``
    at ``span[1]``, and ``end`` after."""

    def __init__(
        self, start: float, end: float, total_steps: int, span: tuple[float, float] = (0.4, 0.8)
    ) -> None:
        self.start, self.end, self.total = start, end, max(1, total_steps)
        self.span = span

    def at(self, steps: int) -> float:
        return self.start + (self.end - self.start) * _ramp(steps / self.total, self.span)


class FallPenalty(_Schedule):
    """The fall penalty over training: ``start`` until ``span[0]`` of the steps, then rising
    linearly to ``end`` at ``span[1]`` (first learn to touch the ball at all, then to stay up
    while kicking)."""


class Curriculum:
    """How much nearer the toe the ball starts (m) over training: ``start`` at first, down
    linearly to 0 at ``until`` of the steps (first touch the ball at all, then reach it)."""

    def __init__(self, start: float, until: float, total_steps: int) -> None:
        self.start, self.until, self.total = start, until, max(1, total_steps)

    def at(self, steps: int) -> float:
        if self.until <= 0:
            return 0.0
        return self.start * max(0.0, 1.0 - steps / (self.until * self.total))


class ExplorationCap(_Schedule):
    """The most the policy's exploration (the log of its actions' standard deviation) may be
    over training: ``start`` until ``span[0]`` of the steps, then falling linearly to ``end`` at
    ``span[1]`` (explore widely while learning to touch and kick, then refine the kick with less
    noise, so that the episodes it learns from are nearly those it will play)."""

    def at(self, steps: int) -> float:
        if self.end >= self.start:  # no cap
            return math.inf
        return super().at(steps)

    def apply(self, agent: Any, steps: int) -> float:
        """Lower the policy's learnt log standard deviations to the cap of the moment; their
        mean after that."""
        import jax.numpy as jnp

        cap = self.at(steps)
        model = agent.models["policy"]
        params = model.state_dict.params
        log_std = params["params"]["log_std"]
        if float(jnp.max(log_std)) > cap:
            log_std = jnp.minimum(log_std, cap)
            capped = {**params["params"], "log_std": log_std}
            model.state_dict = model.state_dict.replace(params={**params, "params": capped})
        return float(jnp.mean(log_std))


class PolicyInputs(gym.vector.VectorWrapper):
    """The vector environment as the learner sees it: flat scaled observations, actions in
    [-1, 1] mapped to targets around the stance; logs every finished episode and sets the fall
    penalty and the ball's start of the moment."""

    def __init__(
        self, env: gym.vector.VectorEnv, template: Policy, log: EpisodeLog, penalty: FallPenalty,
        curriculum: Curriculum, exploration: ExplorationCap, holder: dict[str, Any],
    ) -> None:  # fmt: skip
        super().__init__(env)
        self.exploration = exploration
        self.holder = holder
        self.template = template
        self.log = log
        self.penalty = penalty
        self.curriculum = curriculum
        n = len(OBS_SCALE)
        self.single_observation_space = gym.spaces.Box(-np.inf, np.inf, (n,), np.float32)
        self.observation_space = gym.vector.utils.batch_space(
            self.single_observation_space, self.num_envs
        )
        self.single_action_space = gym.spaces.Box(-1.0, 1.0, (20,), np.float32)
        self.action_space = gym.vector.utils.batch_space(self.single_action_space, self.num_envs)
        self._returns = np.zeros(self.num_envs)

    def _scaled(self, obs: dict[str, Any]) -> np.ndarray:
        self.last_raw = flat_observation(obs)
        scaled: np.ndarray = (self.last_raw * OBS_SCALE).astype(np.float32)
        return scaled

    def _schedule(self) -> None:
        """The fall penalty and the ball's start of the moment, into every environment."""
        penalty = self.penalty.at(self.log.steps)
        closer = self.curriculum.at(self.log.steps)
        for env in self.env.unwrapped.envs:  # type: ignore[attr-defined]
            env.fall_penalty = penalty
            env.ball_closer_m = closer  # read by the next reset
        self.log.fall_penalty = penalty
        if "agent" in self.holder:
            self.log.log_std = self.exploration.apply(self.holder["agent"], self.log.steps)

    def reset(self, **kwargs: Any) -> tuple[Any, dict[str, Any]]:
        self._schedule()
        obs, info = self.env.reset(**kwargs)
        self._returns[:] = 0.0
        return self._scaled(obs), info

    def step(self, actions: Any) -> tuple[Any, Any, Any, Any, dict[str, Any]]:
        targets = self.template.targets(np.asarray(actions, np.float64)).astype(np.float32)
        self._schedule()
        obs, rewards, terminated, truncated, infos = self.env.step(targets)
        self._returns += rewards
        ended = np.logical_or(terminated, truncated)
        if ended.any():
            final = infos.get("final_info", {})
            for i in np.flatnonzero(ended).tolist():
                self.log.episode(float(self._returns[i]), _item(final, "kick_distance_m", i),
                                 _item(final, "max_ball_speed_m_s", i),
                                 bool(_item(final, "fallen", i)),
                                 bool(_item(final, "touched", i)),
                                 _item(final, "ball_closer_m", i))  # fmt: skip
                self._returns[i] = 0.0
        self.log.steps += self.num_envs
        return self._scaled(obs), rewards, terminated, truncated, infos


def _item(batched: dict[str, Any], key: str, i: int) -> float:
    values = batched.get(key)
    return 0.0 if values is None else float(values[i])


class EpisodeLog:
    """``episodes.csv``, progress lines, and the policy file at every progress line."""

    def __init__(self, out: Path, *, every_s: float, export: Any) -> None:
        self.file = (out / "episodes.csv").open("w", newline="")
        self.csv = csv.writer(self.file)
        self.csv.writerow(["env_steps", "episode", "return", "kick_distance_m",
                           "max_ball_speed_m_s", "fallen", "touched", "fall_penalty",
                           "ball_closer_m", "log_std", "wall_s"])  # fmt: skip
        self.steps = 0
        self.fall_penalty = 0.0
        self.log_std = 0.0
        self.episodes = 0
        self.recent: deque[tuple[float, float, float, bool, bool]] = deque(maxlen=200)
        self.started = time.perf_counter()
        self.every_s = every_s
        self.export = export
        self._last_print = self.started

    def episode(
        self, ret: float, kick: float, speed: float, fallen: bool, touched: bool, closer: float
    ) -> None:
        self.episodes += 1
        wall = time.perf_counter() - self.started
        self.csv.writerow([self.steps, self.episodes, round(ret, 4), round(kick, 4),
                           round(speed, 3), int(fallen), int(touched), round(self.fall_penalty, 3),
                           round(closer, 4), round(self.log_std, 3), round(wall, 1)])  # fmt: skip
        self.recent.append((ret, kick, speed, fallen, touched))
        if time.perf_counter() - self._last_print >= self.every_s:
            self.progress()

    def progress(self) -> None:
        self._last_print = time.perf_counter()
        wall = self._last_print - self.started
        r = np.array(self.recent, dtype=np.float64).reshape(-1, 5)
        print(f"steps {self.steps:>8} ({self.steps / max(wall, 1e-9):5.0f}/s)  episodes "
              f"{self.episodes:>6}  last {len(r)}: return {r[:, 0].mean():+.3f}  kick "
              f"{r[:, 1].mean():.2f} m  touched {r[:, 4].mean():4.0%}  ball >= 1 m/s "
              f"{np.mean(r[:, 2] >= 1.0):4.0%}  falls {r[:, 3].mean():4.0%}  {wall:6.0f} s",
              flush=True)  # fmt: skip
        self.file.flush()
        self.export()

    def close(self) -> None:
        self.file.close()


def build_agent(env: Any, args: argparse.Namespace, out: Path) -> Any:
    """skrl's PPO with a small MLP policy (tanh, as robot.learned runs it) and value net."""
    import flax.linen as nn
    import jax.numpy as jnp
    from skrl.agents.jax.ppo import PPO, PPO_CFG
    from skrl.memories.jax import RandomMemory
    from skrl.models.jax import DeterministicMixin, GaussianMixin, Model
    from skrl.resources.preprocessors.jax import RunningStandardScaler

    class PolicyNet(GaussianMixin, Model):  # type: ignore[misc]
        def __init__(self, observation_space: Any, state_space: Any, action_space: Any,
                     device: Any, **kwargs: Any) -> None:  # fmt: skip
            Model.__init__(self, observation_space=observation_space, state_space=state_space,
                           action_space=action_space, device=device, **kwargs)  # fmt: skip
            GaussianMixin.__init__(self, clip_actions=False, clip_log_std=True,
                                   min_log_std=-5.0, max_log_std=1.0)  # fmt: skip

        @nn.compact
        def __call__(self, inputs: dict[str, Any], role: str) -> Any:
            x = inputs["observations"]
            for width in HIDDEN:
                x = nn.tanh(nn.Dense(width)(x))
            # a small last layer: the untrained policy stays near the stance
            last = nn.Dense(self.num_actions, kernel_init=nn.initializers.normal(0.01))
            x = nn.tanh(last(x))
            log_std = self.param("log_std", lambda _: jnp.full(self.num_actions, args.init_log_std))
            return x, {"log_std": log_std}

    class ValueNet(DeterministicMixin, Model):  # type: ignore[misc]
        def __init__(self, observation_space: Any, state_space: Any, action_space: Any,
                     device: Any, **kwargs: Any) -> None:  # fmt: skip
            Model.__init__(self, observation_space=observation_space, state_space=state_space,
                           action_space=action_space, device=device, **kwargs)  # fmt: skip
            DeterministicMixin.__init__(self)

        @nn.compact
        def __call__(self, inputs: dict[str, Any], role: str) -> Any:
            x = inputs["observations"]
            for width in (128, 128):
                x = nn.tanh(nn.Dense(width)(x))
            return nn.Dense(1)(x), {}

    device = env.device
    models: dict[str, Any] = {
        "policy": PolicyNet(env.observation_space, None, env.action_space, device),
        "value": ValueNet(env.observation_space, None, env.action_space, device),
    }
    for role, model in models.items():
        model.init_state_dict(role=role)
    cfg = PPO_CFG()
    cfg.rollouts = args.rollouts
    cfg.learning_epochs = args.epochs
    cfg.mini_batches = 4
    cfg.discount_factor = 0.98
    cfg.gae_lambda = 0.95
    cfg.learning_rate = args.learning_rate
    cfg.value_preprocessor = RunningStandardScaler
    if args.obs_norm:
        # no clipping, so that export_policy folds the standardisation into the first layer
        cfg.observation_preprocessor = RunningStandardScaler
        cfg.observation_preprocessor_kwargs = {"size": env.observation_space, "device": device,
                                               "epsilon": OBS_NORM_EPSILON,
                                               "clip_threshold": 1e9}  # fmt: skip
    cfg.value_preprocessor_kwargs = {"size": 1, "device": device}
    cfg.grad_norm_clip = 1.0
    cfg.entropy_loss_scale = 0.0
    cfg.value_loss_scale = 1.0
    cfg.time_limit_bootstrap = True
    cfg.experiment.directory = str(out / "skrl")
    cfg.experiment.experiment_name = "ppo"
    cfg.experiment.write_interval = max(1, args.rollouts * 4)
    cfg.experiment.checkpoint_interval = max(1, args.timesteps // 5)
    memory = RandomMemory(memory_size=args.rollouts, num_envs=env.num_envs, device=device)
    return PPO(models=models, memory=memory, cfg=cfg, observation_space=env.observation_space,
               action_space=env.action_space, device=device)  # fmt: skip


def export_policy(agent: Any, template: Policy, path: Path) -> Policy:
    """The agent's policy network as a robot.learned policy file."""
    params = agent.models["policy"].state_dict.params["params"]
    layers = []
    for i in range(len(HIDDEN) + 1):
        dense = params[f"Dense_{i}"]
        layers.append(
            (np.asarray(dense["kernel"], np.float64), np.asarray(dense["bias"], np.float64))
        )
    scaler = getattr(agent, "_observation_preprocessor", None)
    if hasattr(scaler, "running_mean"):  # (x - mean) / (std + eps), folded into the first layer
        mean = np.asarray(scaler.running_mean, np.float64)
        std = np.sqrt(np.asarray(scaler.running_variance, np.float64)) + scaler.epsilon
        kernel, bias = layers[0]
        layers[0] = (kernel / std[:, None], bias - (mean / std) @ kernel)
    policy = Policy(**{**_fields(template), "layers": tuple(layers)})
    save_policy(policy, path)
    return policy


def export_error(agent: Any, policy: Policy, raw: np.ndarray) -> float:
    """The largest difference between the agent's mean actions and the exported policy's on
    raw observations (the policy file holds the inputs' standardisation in its first layer)."""
    model = agent.models["policy"]
    scaled = agent._observation_preprocessor((raw * OBS_SCALE).astype(np.float32))
    mean, _ = model.apply(model.state_dict.params, {"observations": scaled}, "policy")
    return float(np.max(np.abs(np.asarray(mean, np.float64) - policy.mean_action(raw))))


def _fields(policy: Policy) -> dict[str, Any]:
    return {name: getattr(policy, name) for name in Policy.__dataclass_fields__}


def evaluate(
    policy: Policy | None, *, episodes: int, seed: int, fall_penalty: float, ball_noise: float,
    robot_class: str = "kid",
) -> dict[str, float]:
    """Seeded episodes of the policy run by the robot's own code (``PolicyMotion``, fed the
    readings as a robot gets them), or of random actions in [-1, 1] when ``policy`` is None."""
    template = policy or policy_template(robot_class)
    env = gym.make(ENV_ID, robot_class=robot_class, steps_per_action=STEPS_PER_ACTION,
                   max_episode_s=EPISODE_S, fall_penalty=fall_penalty,
                   ball_noise_m=ball_noise)  # fmt: skip
    rng = np.random.default_rng(seed)
    rows = []
    for episode in range(episodes):
        obs, info = env.reset(seed=seed + episode)
        motion = PolicyMotion(template) if policy is not None else None
        total, done = 0.0, False
        while not done:
            if motion is not None:
                joints = dict(zip(MOTOR_NAMES, obs["joints"].tolist(), strict=True))
                motion.sense(joints, obs["accelerometer"].tolist(), obs["gyro"].tolist())
                targets = motion.step(0.008)
                for _ in range(STEPS_PER_ACTION - 1):  # one decision per environment step
                    motion.step(0.008)
                action = np.array([targets[name] for name in MOTOR_NAMES], np.float32)
            else:
                action = template.targets(rng.uniform(-1.0, 1.0, 20)).astype(np.float32)
            obs, reward, terminated, truncated, info = env.step(action)
            total += float(reward)
            done = terminated or truncated
        rows.append((total, info["kick_distance_m"], info["max_ball_speed_m_s"], info["fallen"]))
    env.close()
    r = np.array(rows, dtype=np.float64)
    return {"episodes": episodes, "mean_return": round(float(r[:, 0].mean()), 3),
            "mean_kick_distance_m": round(float(r[:, 1].mean()), 3),
            "ball_1m_s_share": round(float(np.mean(r[:, 2] >= 1.0)), 3),
            "fall_share": round(float(r[:, 3].mean()), 3)}  # fmt: skip


def training_figures(path: Path, n: int = 200) -> dict[str, dict[str, float]]:
    """The training episodes' figures over the first and the last ``n`` (the exploring
    policy): mean ball travel, return, shares touched, with the ball >= 1 m/s, fallen."""
    with path.open() as f:
        rows = list(csv.DictReader(f))
    figures = {}
    for name, part in (("first", rows[:n]), ("last", rows[-n:])):
        if not part:
            continue
        col = {k: np.array([float(r[k]) for r in part]) for k in part[0] if k != "episode"}
        figures[name] = {
            "episodes": len(part),
            "mean_kick_distance_m": round(float(col["kick_distance_m"].mean()), 3),
            "mean_return": round(float(col["return"].mean()), 3),
            "touched_share": round(float(col["touched"].mean()), 3),
            "ball_1m_s_share": round(float(np.mean(col["max_ball_speed_m_s"] >= 1.0)), 3),
            "fall_share": round(float(col["fallen"].mean()), 3),
        }
    return figures


def plot(out: Path, random_return: float, learned_return: float) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with (out / "episodes.csv").open() as f:
        rows = list(csv.DictReader(f))
    steps = np.array([float(r["env_steps"]) for r in rows])
    returns = np.array([float(r["return"]) for r in rows])
    window = max(1, min(200, len(returns) // 10))

    def mean(values: np.ndarray) -> np.ndarray:
        return np.convolve(values, np.ones(window) / window, mode="valid")

    smooth = mean(returns)
    fig, (ax, bx) = plt.subplots(2, 1, figsize=(7, 6.5), dpi=110, sharex=True)
    ax.plot(steps, returns, ".", ms=1.5, alpha=0.25, color="tab:blue", label="episode return")
    ax.plot(steps[window - 1 :], smooth, color="tab:blue", label=f"mean of {window} episodes")
    ax.axhline(random_return, color="tab:red", ls="--", label="random policy")
    ax.axhline(learned_return, color="tab:green", ls=":", label="learned policy (robot runner)")
    ax.set_ylabel("return (shaped: ball progress, toe\napproach, touch, - still, - falls)")
    ax.set_title("hlvs/StandKick-v0, PPO (skrl, JAX CPU)")
    ax.legend(loc="lower right", fontsize=8)
    ax.grid(alpha=0.3)
    column = {name: np.array([float(r[name]) for r in rows]) for name in rows[0]}
    x = steps[window - 1 :]
    bx.plot(x, mean(column["kick_distance_m"]), color="tab:blue", label="kick distance (m)")
    bx.plot(x, mean(column["max_ball_speed_m_s"] >= 1.0), color="tab:orange",
            label="share with ball >= 1 m/s")  # fmt: skip
    bx.plot(x, mean(column["fallen"]), color="tab:red", label="share fallen")
    if "fall_penalty" in column:
        bx.plot(steps, column["fall_penalty"], color="gray", ls=":", label="fall penalty")
    if "log_std" in column:
        bx.plot(steps, np.exp(column["log_std"]), color="tab:purple", ls="--",
                label="exploration (std of the actions, in [-1, 1])")  # fmt: skip
    bx.set_xlabel(f"environment steps ({8 * STEPS_PER_ACTION} ms each)")
    bx.set_ylabel(f"mean of {window} episodes")
    bx.legend(loc="upper left", fontsize=8)
    bx.grid(alpha=0.3)
    fig.tight_layout()
    path = out / "learning_curve.png"
    fig.savefig(path)
    plt.close(fig)
    return path


def plot_runs(runs: list[Path], path: Path, window: int = 200) -> Path:
    """The learning curves of several runs (seeds) in one figure: the ball's travel and the
    shares of episodes touching the ball and falling, each a mean of ``window`` training
    episodes."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (ax, bx, cx) = plt.subplots(3, 1, figsize=(7, 8), dpi=110, sharex=True)
    for run in runs:
        with (run / "episodes.csv").open() as f:
            rows = list(csv.DictReader(f))
        summary = json.loads((run / "summary.json").read_text())
        steps = np.array([float(r["env_steps"]) for r in rows])
        w = max(1, min(window, len(rows)))

        def mean(key: str, rows: list[dict[str, str]] = rows, w: int = w) -> np.ndarray:
            values = np.array([float(r[key]) for r in rows])
            return np.convolve(values, np.ones(w) / w, mode="valid")

        label = f"seed {summary['seed']}"
        ax.plot(steps[w - 1 :], mean("kick_distance_m"), label=label)
        bx.plot(steps[w - 1 :], mean("touched"), label=label)
        cx.plot(steps[w - 1 :], mean("fallen"), label=label)
    ax.axhline(1.0, color="gray", ls=":", lw=1)
    ax.set_ylabel(f"ball travel (m), mean of {window} episodes")
    ax.set_title("hlvs/StandKick-v0, PPO (skrl, JAX CPU): training episodes")
    ax.legend(loc="upper left", fontsize=8)
    ax.grid(alpha=0.3)
    bx.set_ylabel(f"share touching the ball, of {window}")
    bx.grid(alpha=0.3)
    cx.set_ylabel(f"share fallen, of {window}")
    cx.set_xlabel(f"environment steps ({8 * STEPS_PER_ACTION} ms each)")
    cx.grid(alpha=0.3)
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    plt.close(fig)
    return path


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seed", type=int, default=1, help="seed of the networks and episodes")
    parser.add_argument("--out", type=Path, default=Path("runs/stand_kick"), help="output folder")
    parser.add_argument("--class", dest="robot_class", choices=("kid", "adult"), default="kid",
                        help="the robot class: its default robot, ball and pitch")  # fmt: skip
    parser.add_argument(
        "--env-steps",
        type=int,
        default=48_000,
        help="environment steps to train for (all environments together)",
    )
    parser.add_argument("--envs", type=int, default=16, help="environments in the vector")
    parser.add_argument(
        "--remotes",
        type=int,
        default=0,
        help="run the environments in this many simulator containers (0: here)",
    )
    parser.add_argument("--rollouts", type=int, default=16, help="steps per environment per update")
    parser.add_argument("--learning-rate", type=float, default=1e-3)
    parser.add_argument("--epochs", type=int, default=8, help="PPO epochs per update")
    parser.add_argument("--obs-norm", action=argparse.BooleanOptionalAction, default=True,
                        help="standardise the policy's inputs by their running mean and std "
                        "(--no-obs-norm: the fixed scales alone)")  # fmt: skip
    parser.add_argument("--init-log-std", type=float, default=-1.2, help="initial exploration")
    parser.add_argument("--final-log-std", type=float, default=-2.5,
                        help="the exploration's cap falls to this from --refine-from to "
                        "--refine-until (not below --init-log-std: no cap)")  # fmt: skip
    parser.add_argument("--fall-penalty", type=float, default=1.0,
                        help="reward lost by a fall, until --refine-from")  # fmt: skip
    parser.add_argument("--fall-penalty-end", type=float, default=3.0,
                        help="... rising to this at --refine-until (default 3)")  # fmt: skip
    parser.add_argument("--refine-from", type=float, default=0.4,
                        help="share of the steps where the fall penalty starts rising and the "
                        "exploration's cap falling ...")  # fmt: skip
    parser.add_argument("--refine-until", type=float, default=0.8,
                        help="... and where they reach their ends")  # fmt: skip
    parser.add_argument("--ball-noise", type=float, default=0.01, help="ball placement noise (m)")
    parser.add_argument(
        "--curriculum-m",
        type=float,
        default=0.03,
        help="the ball starts this much nearer the toe at first (m) ...",
    )
    parser.add_argument(
        "--curriculum-until",
        type=float,
        default=0.3,
        help="... and where it stands in the skill from this share of the steps",
    )
    parser.add_argument(
        "--progress-s", type=float, default=30.0, help="seconds between progress lines"
    )
    parser.add_argument("--eval-episodes", type=int, default=50, help="episodes per evaluation")
    parser.add_argument("--plot-runs", type=Path, nargs="+", metavar="OUT",
                        help="plot these finished runs' learning curves in one figure "
                        "(to --out, a .png) instead of training")  # fmt: skip
    args = parser.parse_args(argv)
    if args.plot_runs:
        print(plot_runs(args.plot_runs, args.out))
        return 0

    import jax
    from skrl import config as skrl_config
    from skrl.envs.wrappers.jax import wrap_env
    from skrl.trainers.jax import SequentialTrainer
    from skrl.utils import set_seed

    # skrl's default JAX device is "cuda:0" whatever the machine has; on a CPU machine it warns
    # "Invalid device specification (cuda:0)" and falls back. JAX's own first device is the GPU
    # where one is present and the CPU otherwise.
    skrl_config.jax.device = jax.devices()[0]

    out: Path = args.out
    out.mkdir(parents=True, exist_ok=True)
    set_seed(args.seed)
    num_envs = args.remotes or args.envs
    args.timesteps = math.ceil(args.env_steps / num_envs)
    template = policy_template(args.robot_class)
    started = time.perf_counter()
    vec = make_vector(ENV_ID, remotes=args.remotes or None, num_envs=num_envs,
                      robot_class=args.robot_class,
                      steps_per_action=STEPS_PER_ACTION, max_episode_s=EPISODE_S,
                      fall_penalty=args.fall_penalty, ball_noise_m=args.ball_noise)  # fmt: skip
    holder: dict[str, Any] = {}
    log = EpisodeLog(
        out,
        every_s=args.progress_s,
        export=lambda: export_policy(holder["agent"], template, out / "policy.npz"),
    )
    end = args.fall_penalty_end
    span = (args.refine_from, args.refine_until)
    penalty = FallPenalty(args.fall_penalty, end, args.timesteps * num_envs, span)
    curriculum = Curriculum(args.curriculum_m, args.curriculum_until, args.timesteps * num_envs)
    exploration = ExplorationCap(
        args.init_log_std, args.final_log_std, args.timesteps * num_envs, span
    )
    inputs = PolicyInputs(vec, template, log, penalty, curriculum, exploration, holder)
    env = wrap_env(inputs, wrapper="gymnasium")
    agent = build_agent(env, args, out)
    holder["agent"] = agent
    print(f"training {ENV_ID} ({args.robot_class}): {args.timesteps * num_envs} environment "
          f"steps over {num_envs} environments ({'remotes' if args.remotes else 'in-process'}), "
          f"seed {args.seed}, output in {out}", flush=True)  # fmt: skip
    trainer = SequentialTrainer(
        env=env, agents=agent,
        cfg={"timesteps": args.timesteps, "headless": True, "disable_progressbar": True,
             "close_environment_at_exit": False},
    )  # fmt: skip
    trainer.train()
    log.progress()
    log.close()
    env.close()
    train_s = time.perf_counter() - started
    policy = load_policy(out / "policy.npz")  # what the robot would load
    exported = export_error(agent, policy, inputs.last_raw.astype(np.float64))
    eval_seed = 10_000 + args.seed
    same: dict[str, Any] = {"episodes": args.eval_episodes, "seed": eval_seed,
                            "fall_penalty": end, "ball_noise": args.ball_noise,
                            "robot_class": args.robot_class}  # fmt: skip
    learned = evaluate(policy, **same)
    baseline = evaluate(None, **same)
    png = plot(out, baseline["mean_return"], learned["mean_return"])
    summary = {
        "example": "learn_stand_kick", "env": ENV_ID, "robot_class": args.robot_class,
        "seed": args.seed,
        "env_steps": log.steps, "episodes": log.episodes, "fall_penalty": [args.fall_penalty, end],
        "curriculum_m": [args.curriculum_m, args.curriculum_until],
        "log_std": [args.init_log_std, args.final_log_std],
        "refine": [args.refine_from, args.refine_until], "obs_norm": args.obs_norm,
        "train_wall_s": round(train_s, 1), "training": training_figures(out / "episodes.csv"),
        "steps_per_s": round(log.steps / train_s, 1), "learned": learned, "random": baseline,
        "policy": str(out / "policy.npz"), "export_max_error": exported, "plot": str(png),
        "wall_s": round(time.perf_counter() - started, 1),
    }  # fmt: skip
    (out / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
    print(json.dumps(summary))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
