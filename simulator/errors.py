"""Errors of the simulator package.

Tree::

    SimulatorError
    ├── ModelError           a team robot model package that cannot be used (every problem)
    ├── PhysicsDivergence    MuJoCo reported instability (carries its warning and the policy)
    ├── ApiError             robot API misuse on the simulator side
    ├── UnknownDeviceError   a device name a robot does not have (world device access)
    ├── ReplayError          a replay file that cannot be read
    ├── RenderError          a video that could not be produced (ffmpeg missing or failing)
    ├── OffscreenGLError     no offscreen OpenGL back end works (each one tried, with why)
    └── GpuRenderError       gpu "on" but the simulator cannot render on the GPU

A match_spec.json that does not describe a match raises :class:`contracts.errors.ContractError`.
Unknown robot model names raise :class:`robot.errors.UnknownModelError` (one class for the
simulator and the robot-side motion code).
"""

from __future__ import annotations

from dataclasses import dataclass

from robot import UnknownModelError

__all__ = [
    "ApiError",
    "ModelError",
    "ModelProblem",
    "PhysicsDivergence",
    "RenderError",
    "ReplayError",
    "SimulatorError",
    "UnknownDeviceError",
    "UnknownModelError",
]


class SimulatorError(Exception):
    """Root of every error the simulator package raises."""


@dataclass(frozen=True, slots=True, kw_only=True)
class ModelProblem:
    """One problem of a team robot model: the file, where in it, and what is wrong."""

    source: str
    where: str  # JSON pointer in the manifest, or the element / link / rule
    reason: str
    severity: str = "error"  # "warning": allowed in friendlies, refused in official matches;
    # "note": what of the file the world leaves out or replaces (never refused)

    def __str__(self) -> str:
        text = f"{self.source}: {self.where or '/'}: {self.reason}"
        return f"{self.severity}: {text}" if self.severity in ("warning", "note") else text


class ModelError(SimulatorError):
    """A team robot model package that cannot be loaded; carries every problem found."""

    def __init__(self, problems: list[ModelProblem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class PhysicsDivergence(SimulatorError):
    def __init__(self, *, sim_time_ms: int, warning: str, policy: str) -> None:
        self.sim_time_ms = sim_time_ms
        self.warning = warning
        self.policy = policy
        super().__init__(f"physics diverged at {sim_time_ms} ms: {warning} (policy: {policy})")


class ApiError(SimulatorError):
    """Robot API error on the simulator side."""


class UnknownDeviceError(SimulatorError):
    """A device name (or robot) the world does not have; the API answers with a warning."""

    def __init__(self, *, robot: str, name: str, kind: str) -> None:
        self.robot = robot
        self.name = name
        self.kind = kind
        what = f"{kind} {name!r}" if name else kind
        super().__init__(f"{robot}: no such {what}")


class ReplayError(SimulatorError):
    """A replay file that cannot be read (names the file and what was wrong)."""

    def __init__(self, *, path: str, reason: str) -> None:
        self.path = path
        self.reason = reason
        super().__init__(f"{path}: {reason}")


class RenderError(SimulatorError):
    """A video that could not be produced."""

    def __init__(self, *, output: str, reason: str) -> None:
        self.output = output
        self.reason = reason
        super().__init__(f"{output}: {reason}")


class OffscreenGLError(SimulatorError):
    """No offscreen OpenGL back end could make a context."""

    def __init__(self, *, tried: tuple[tuple[str, str], ...], from_environment: bool) -> None:
        self.tried = tried
        self.from_environment = from_environment
        attempts = "; ".join(f"MUJOCO_GL={name}: {reason}" for name, reason in tried)
        if from_environment:
            hint = "unset MUJOCO_GL to let the program try egl and osmesa"
        else:
            hint = "install Mesa's EGL (libegl1, libegl-mesa0) or OSMesa (libosmesa6)"
        super().__init__(f"no offscreen OpenGL back end works (tried {attempts}); {hint}")


class GpuRenderError(SimulatorError):
    """``gpu`` "on" (``HLVS_GPU=on``) but EGL gives no hardware renderer in this process."""

    def __init__(self, *, reason: str) -> None:
        self.reason = reason
        super().__init__(
            f'gpu "on": the simulator cannot render on the GPU ({reason}); check the NVIDIA '
            'container toolkit on the host (graphics capability) or set gpu to "auto" or "off"'
        )
