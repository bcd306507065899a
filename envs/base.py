"""The part every hlvs environment shares: a session behind it, spaces, seeding, the trainer."""

from __future__ import annotations

from typing import Any, Protocol, SupportsFloat, cast

import gymnasium as gym
import numpy as np
import numpy.typing as npt

from envs.errors import EnvConfigError, EnvStateError
from envs.frame import Frame
from envs.session_spec import ResetOptions, ResetRequest, SessionSpec
from envs.spaces import action_space, observation_space, observe

FloatArray = npt.NDArray[np.float64]
SEED_LIMIT = 2**31 - 1


class Session(Protocol):
    """The world behind an environment: in this process or on a remote simulator."""

    def reset(self, request: ResetRequest) -> Frame: ...

    def step(self, targets: FloatArray | list[float]) -> Frame: ...

    def place_ball(
        self, x_m: float, y_m: float, vx_m_s: float = 0.0, vy_m_s: float = 0.0
    ) -> None: ...

    def place_robot(
        self, color: str, number: int, x_m: float, y_m: float, yaw_rad: float
    ) -> None: ...

    def set_game_state(self, state: str) -> None: ...

    def drop_ball(self, x_m: float = 0.0, y_m: float = 0.0) -> None: ...

    def close(self) -> None: ...


def open_session(spec: SessionSpec, remotes: int | str | None) -> tuple[Session, Any]:
    """The session for ``remotes``: None runs the world in this process; an int starts that
    many simulator containers (the environment uses the first); ``"hlvs://host:port,..."``
    connects to simulators already running; ``"slurm:N"`` has a Slurm cluster run them.
    Returns the session and what owns the remotes."""
    if remotes is None or remotes == 0:
        from envs.session import LocalSession

        return LocalSession(spec), None
    from envs.remote_pool import RemotePool

    pool = RemotePool.open(remotes)
    try:
        return pool.session(0, spec), pool
    except BaseException:
        pool.close()
        raise


class HlvsEnv(gym.Env[dict[str, Any], np.ndarray]):
    """Base of the hlvs environments; subclasses build the reset request and the reward."""

    metadata: dict[str, Any] = {"render_modes": ["rgb_array"], "render_fps": 25}

    def __init__(
        self,
        *,
        spec: SessionSpec,
        other_robots: int,
        game: bool,
        remotes: int | str | None = None,
        render_mode: str | None = None,
        session: Session | None = None,
    ) -> None:
        if render_mode not in (None, "rgb_array"):
            raise EnvConfigError(
                field="render_mode", value=render_mode, expected="None or 'rgb_array'",
                choices=["rgb_array"],
            )  # fmt: skip
        self.session_spec = spec
        self.render_mode = render_mode
        self.action_space = action_space(spec.model)
        self.observation_space = observation_space(
            spec.model, camera=spec.camera, perception=spec.perception,
            other_robots=other_robots, game=game,
        )  # fmt: skip
        self._owner: Any = None  # what owns the remotes; closed with the environment
        self._remote: tuple[Any, int] | None = None  # (pool, index) replacing a crashed remote
        if session is None:
            session, self._owner = open_session(spec, remotes)
            if self._owner is not None:
                self._remote = (self._owner, 0)
        self.session: Session = session
        self.frame: Frame | None = None
        self._closed = False

    # --- gymnasium ---------------------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, Any], dict[str, Any]]:
        super().reset(seed=seed)
        if self._closed:
            raise EnvStateError(operation="reset", reason="the environment is closed")
        world_seed = int(self.np_random.integers(0, SEED_LIMIT))
        request = self.reset_request(world_seed, cast("ResetOptions", options or {}))
        if getattr(self.session, "crashed", False):
            self._replace_crashed()
        self.frame = self.session.reset(request)
        self.on_reset(self.frame)
        return observe(self.frame, self.observation_space), self.info(self.frame)  # type: ignore[arg-type]

    def step(
        self, action: np.ndarray
    ) -> tuple[dict[str, Any], SupportsFloat, bool, bool, dict[str, Any]]:
        frame = self.session.step(self.targets(action))
        return self.finish_step(frame)

    def targets(self, action: np.ndarray) -> FloatArray:
        """The motor targets of ``action`` (checked: after reset, right shape)."""
        if self.frame is None:
            raise EnvStateError(operation="step", reason="call reset() before step()")
        targets = np.asarray(action, dtype=np.float64).reshape(-1)
        if targets.shape != self.action_space.shape:
            raise EnvConfigError(
                field="action", value=f"shape {targets.shape}",
                expected=f"shape {self.action_space.shape} (motor targets, rad)",
            )  # fmt: skip
        return targets

    def finish_step(self, frame: Frame) -> tuple[dict[str, Any], float, bool, bool, dict[str, Any]]:
        """Reward, ends and observation of the frame a step produced."""
        assert self.frame is not None
        previous = self.frame
        self.frame = frame
        reward, terminated, truncated = self.judge(previous, frame)
        obs = observe(frame, self.observation_space)  # type: ignore[arg-type]
        return obs, reward, terminated, truncated, self.info(frame)

    def render(self) -> np.ndarray | None:
        if self.render_mode != "rgb_array":
            return None
        if self.frame is None or self.frame.image is None:
            raise EnvStateError(
                operation="render", reason="rgb_array needs camera=True and a reset() first"
            )
        return np.ascontiguousarray(self.frame.image[:, :, ::-1])

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        self.session.close()
        if self._owner is not None:
            self._owner.close()

    def attach_remote(self, pool: Any, index: int) -> None:
        """Remote ``index`` of ``pool`` (a vector environment's) replaces a crashed session."""
        self._remote = (pool, index)

    def _replace_crashed(self) -> None:
        """A remote that crashed is replaced when the pool started it; else RemoteError."""
        if self._remote is None:
            from envs.errors import RemoteError

            raise RemoteError(address=str(getattr(self.session, "address", "?")),
                              reason="crashed; no pool to replace it")  # fmt: skip
        pool, index = self._remote
        self.session.close()
        self.session = pool.replace(index, self.session_spec)

    # --- trainer -----------------------------------------------------------------------------

    @property
    def trainer(self) -> Session:
        """Place the ball and robots, set the game state, drop the ball (between steps)."""
        return self.session

    # --- for subclasses ----------------------------------------------------------------------

    def reset_request(self, world_seed: int, options: ResetOptions) -> ResetRequest:
        return ResetRequest(seed=world_seed)

    def on_reset(self, frame: Frame) -> None:
        return None

    def judge(self, previous: Frame, frame: Frame) -> tuple[float, bool, bool]:
        raise NotImplementedError

    def info(self, frame: Frame) -> dict[str, Any]:
        return {"sim_time_ms": frame.sim_time_ms}
