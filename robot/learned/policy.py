"""A learned policy as plain arrays in a ``.npz`` file, run with numpy.

The network is a multilayer perceptron with ``tanh`` after every layer, the last included (its
output is the mean action in [-1, 1]). Its input is the robot API's own readings, scaled:
``[joint angles (rad, in motors order), accelerometer (m/s^2), gyro (rad/s), time (s since the
skill started)] * obs_scale``. Its output becomes motor targets
``clip(stance + action_scale * a, low, high)``. A new action is chosen every
``control_period_ms``; the skill lasts ``duration_s``.

Arrays in the file: ``format`` (``"hlvs-policy/1"``), ``skill``, ``motors``, ``layers`` (the
count), ``w0``, ``b0``, ``w1``, ``b1``, ... (``w`` of shape inputs x outputs), ``obs_scale``,
``stance``, ``action_scale``, ``low``, ``high``, ``control_period_ms``, ``duration_s``.
"""

from __future__ import annotations

import math
import zipfile
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import numpy.typing as npt

from robot.errors import RobotError

FORMAT = "hlvs-policy/1"
# where a learned kick from a stand expects the ball: this far in front of the torso (1 to 3 cm
# in front of the right toe of kid-default in its stance) and one foot's width to the right
KICK_BALL_AHEAD_M = 0.185
KICK_BALL_RIGHT_M = 0.075
# the same spot for each robot model: (ahead, right) of the torso (m)
KICK_BALL_SPOTS: dict[str, tuple[float, float]] = {
    "kid-default": (KICK_BALL_AHEAD_M, KICK_BALL_RIGHT_M),
    "adult-default": (0.33, 0.15),
}
KICK_MODELS = tuple(KICK_BALL_SPOTS)
# the servo gains (P, I, D) the policies learn with: the learning environments never send the
# robot API's MotorPID, so their robot has the simulator's defaults, Webots' P = 10 (1/s); a
# robot that tunes its servos otherwise (the stub's 30) plays a policy with these, or the
# policy's targets, chosen for a slower servo, throw it over
LEARNT_SERVO_PID: tuple[float, float, float] = (10.0, 0.0, 0.0)
FloatArray = npt.NDArray[np.float64]


def kick_ball_offset(model: str) -> tuple[float, float]:
    """Where a learned right-foot kick of ``model`` expects the ball: (ahead, right) of the
    torso (m); a model without one is a KeyError."""
    return KICK_BALL_SPOTS[model]


class PolicyFileError(RobotError):
    """A policy file that is missing, unreadable or not what it should be."""

    def __init__(self, *, path: Path, field: str, expected: str) -> None:
        self.path = path
        self.field = field
        self.expected = expected
        super().__init__(f"policy file {path}: {field}: expected {expected}")


@dataclass(frozen=True, slots=True, kw_only=True)
class Policy:
    skill: str
    motors: tuple[str, ...]
    layers: tuple[tuple[FloatArray, FloatArray], ...]  # (weights inputs x outputs, biases)
    obs_scale: FloatArray
    stance: FloatArray
    action_scale: FloatArray
    low: FloatArray
    high: FloatArray
    control_period_ms: int
    duration_s: float

    @property
    def n_inputs(self) -> int:
        return int(self.layers[0][0].shape[0])

    def observation(
        self,
        joints: Mapping[str, float],
        accel: Sequence[float],
        gyro: Sequence[float],
        time_s: float,
    ) -> FloatArray:
        """The network's input from the robot API's readings (a missing joint reads 0)."""
        raw = [joints.get(name, 0.0) for name in self.motors]
        return np.array([*raw, *accel, *gyro, time_s], dtype=np.float64)

    def mean_action(self, observation: FloatArray) -> FloatArray:
        """The network's output in [-1, 1] for a raw observation."""
        x = np.asarray(observation, dtype=np.float64) * self.obs_scale
        for weights, biases in self.layers:
            x = np.tanh(x @ weights + biases)
        return x

    def targets(self, action: FloatArray) -> FloatArray:
        """Motor targets (rad, ``motors`` order) of an action in [-1, 1]."""
        clipped = np.clip(action, -1.0, 1.0)
        out: FloatArray = np.clip(self.stance + self.action_scale * clipped, self.low, self.high)
        return out

    def act(self, observation: FloatArray) -> FloatArray:
        return self.targets(self.mean_action(observation))


def save_policy(policy: Policy, path: Path) -> None:
    """Write ``policy`` to ``path`` (``.npz``)."""
    arrays: dict[str, npt.NDArray[np.generic]] = {
        "format": np.array(FORMAT),
        "skill": np.array(policy.skill),
        "motors": np.array(policy.motors),
        "layers": np.array(len(policy.layers)),
        "obs_scale": policy.obs_scale,
        "stance": policy.stance,
        "action_scale": policy.action_scale,
        "low": policy.low,
        "high": policy.high,
        "control_period_ms": np.array(policy.control_period_ms),
        "duration_s": np.array(policy.duration_s),
    }
    for i, (weights, biases) in enumerate(policy.layers):
        arrays[f"w{i}"] = weights
        arrays[f"b{i}"] = biases
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".tmp.npz")
    np.savez(tmp, **arrays)  # type: ignore[arg-type]
    tmp.replace(path)


def load_policy(path: Path) -> Policy:
    """Read a policy file; anything wrong raises :class:`PolicyFileError` naming the field."""
    path = Path(path)
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {key: data[key] for key in data.files}
    except FileNotFoundError as exc:
        raise PolicyFileError(path=path, field="/", expected="an existing file (none is there)"
                              ) from exc
    except (OSError, ValueError, EOFError, zipfile.BadZipFile) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else \
            str(exc).split(". ")[0]
        if isinstance(exc, ValueError) and "pickled" in reason:  # numpy's guess for any file
            reason = "not a .npz archive"
        raise PolicyFileError(
            path=path, field="/",
            expected=f"a .npz file written by save_policy (not readable as one: {reason})",
        ) from exc
    if str(arrays.get("format", "")) != FORMAT:
        raise PolicyFileError(path=path, field="/format", expected=repr(FORMAT))
    motors = tuple(str(m) for m in _get(arrays, path, "motors").tolist())
    n = len(motors)
    count = int(_get(arrays, path, "layers"))
    layers = []
    inputs = n + 3 + 3 + 1
    for i in range(count):
        w = _get(arrays, path, f"w{i}").astype(np.float64)
        b = _get(arrays, path, f"b{i}").astype(np.float64)
        if w.ndim != 2 or w.shape[0] != inputs or b.shape != (w.shape[1],):
            raise PolicyFileError(path=path, field=f"/w{i}",
                                  expected=f"weights {inputs} x k and biases of k")  # fmt: skip
        layers.append((w, b))
        inputs = w.shape[1]
    if not layers or inputs != n:
        raise PolicyFileError(
            path=path, field="/layers", expected=f"at least 1, the last with {n} outputs"
        )
    vectors = {}
    for key, size in (
        ("obs_scale", n + 7),
        ("stance", n),
        ("action_scale", n),
        ("low", n),
        ("high", n),
    ):
        value = _get(arrays, path, key).astype(np.float64)
        if value.shape != (size,) or not np.all(np.isfinite(value)):
            raise PolicyFileError(path=path, field=f"/{key}", expected=f"{size} finite numbers")
        vectors[key] = value
    period = int(_get(arrays, path, "control_period_ms"))
    duration = float(_get(arrays, path, "duration_s"))
    if period < 1 or not (math.isfinite(duration) and duration > 0):
        raise PolicyFileError(path=path, field="/control_period_ms",
                              expected="a period >= 1 ms and a duration > 0 s")  # fmt: skip
    return Policy(
        skill=str(_get(arrays, path, "skill")), motors=motors, layers=tuple(layers),
        obs_scale=vectors["obs_scale"], stance=vectors["stance"],
        action_scale=vectors["action_scale"], low=vectors["low"], high=vectors["high"],
        control_period_ms=period, duration_s=duration,
    )  # fmt: skip


def _get(
    arrays: Mapping[str, npt.NDArray[np.generic]], path: Path, key: str
) -> npt.NDArray[np.generic]:
    if key not in arrays:
        raise PolicyFileError(path=path, field=f"/{key}", expected="present")
    return arrays[key]
