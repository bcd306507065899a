"""What a session builds: plain, JSON-serialisable settings (they travel to remote simulators).

A session is one world with one learning robot (its motors driven by the environment's actions)
and optionally stub robots and the referee with its GameController. ``to_dict`` / ``from_dict``
carry it over the trainer channel of a remote.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field, fields
from typing import Any, TypedDict

from contracts import ENVIRONMENT, MIN_PLAYING_S, JSONObject, TimingError, fit_ready
from envs.errors import EnvConfigError

LOOKS = ("fixed", "random")
SENSOR_MODES = ("ideal", "league", "random")

FIELD_CLASSES = ("kid", "adult")
ROLES = ("striker", "goalie", "defender", "idle")


@dataclass(frozen=True, slots=True, kw_only=True)
class StubSpec:
    """A stub robot played by the session (in-process controller, idealised ball perception)."""

    color: str  # "red" | "blue"
    number: int
    role: str = "striker"
    x_m: float = 0.0  # starting pose in the team's own frame (own goal at x < 0)
    y_m: float = 0.0
    yaw_rad: float = 0.0


@dataclass(frozen=True, slots=True, kw_only=True)
class SessionSpec:
    field_class: str = "kid"
    model: str = "kid-default"
    learner_color: str = "red"
    learner_number: int = 1
    learner_pose: tuple[float, float, float] = (-1.0, 0.0, 0.0)  # team frame, for matches
    stubs: tuple[StubSpec, ...] = ()
    referee: bool = False  # run the GameController and the automatic referee
    half_duration_s: float = ENVIRONMENT.half_duration_s
    minimum_play_s: float = MIN_PLAYING_S  # PLAYING each half keeps (0: not meant to play)
    steps_per_action: int = 1  # basic steps (8 ms) per environment step
    camera: bool = False
    perception: bool = False
    perception_noise: float = 0.0
    perception_range_m: float = 10.0
    physics_dt_s: float = 0.002
    look: str = "fixed"  # "random": each episode its own turf, ball, background and light
    texture_seed: int = 0  # the look of a "fixed" session
    sensors: str = "ideal"  # "league" or "random": noisy sensors and camera (envs.randomization)

    def __post_init__(self) -> None:
        if self.field_class not in FIELD_CLASSES:
            raise EnvConfigError(
                field="field_class", value=self.field_class, expected="'kid' or 'adult'",
                choices=FIELD_CLASSES,
            )  # fmt: skip
        if self.learner_color not in ("red", "blue"):
            raise EnvConfigError(
                field="learner_color", value=self.learner_color, expected="'red' or 'blue'",
                choices=("red", "blue"),
            )  # fmt: skip
        if not 1 <= self.steps_per_action <= 125:
            raise EnvConfigError(
                field="steps_per_action", value=self.steps_per_action, expected="1..125"
            )
        if self.look not in LOOKS:
            raise EnvConfigError(
                field="look", value=self.look, expected=f"one of {list(LOOKS)}", choices=LOOKS
            )
        if self.sensors not in SENSOR_MODES:
            raise EnvConfigError(
                field="sensors", value=self.sensors, expected=f"one of {list(SENSOR_MODES)}",
                choices=SENSOR_MODES,
            )  # fmt: skip
        if self.perception_noise < 0:
            raise EnvConfigError(
                field="perception_noise", value=self.perception_noise, expected="a number >= 0"
            )
        if self.referee:
            try:
                fit_ready(self.half_duration_s, ENVIRONMENT.ready_duration_s,
                          minimum_s=self.minimum_play_s)
            except TimingError as exc:
                raise EnvConfigError(field="half_duration_s", value=self.half_duration_s,
                                     expected=f"a longer half (or minimum_play_s 0): {exc}"
                                     ) from None

    @property
    def ready_duration_s(self) -> float:
        """READY of this session's halves (:data:`contracts.timing.ENVIRONMENT`); the clock
        stands still in it, so it never eats into the half."""
        ready, _warning = fit_ready(self.half_duration_s, ENVIRONMENT.ready_duration_s,
                                    minimum_s=self.minimum_play_s)
        return ready
        for stub in self.stubs:
            if stub.role not in ROLES:
                raise EnvConfigError(
                    field="stubs[].role", value=stub.role, expected=f"one of {list(ROLES)}",
                    choices=ROLES,
                )  # fmt: skip

    def to_dict(self) -> JSONObject:
        """The settings as JSON (the remote protocol's ``open``)."""
        return asdict(self)

    @classmethod
    def from_dict(cls, data: dict[str, Any]) -> SessionSpec:
        known = {f.name for f in fields(cls)}
        unknown = sorted(set(data) - known)
        if unknown:
            raise EnvConfigError(
                field=unknown[0], value=data[unknown[0]], expected="a session setting",
                choices=sorted(known),
            )  # fmt: skip
        values = dict(data)
        if "stubs" in values:
            values["stubs"] = tuple(StubSpec(**s) for s in values["stubs"])
        if "learner_pose" in values:
            values["learner_pose"] = tuple(values["learner_pose"])
        return cls(**values)


class ResetOptions(TypedDict, total=False):
    """The ``options`` of ``reset()`` an environment reads (each one its own; see its docs)."""

    ball_x_m: float
    ball_y_m: float
    robot_pose: tuple[float, float, float] | list[float]  # x, y, yaw


@dataclass(frozen=True, slots=True, kw_only=True)
class ResetRequest:
    """Where to put things at reset (world frame); ``None`` keeps the session's default."""

    seed: int
    learner_pose: tuple[float, float, float] | None = None
    ball_xy: tuple[float, float] | None = None
    extra: dict[str, Any] = field(default_factory=dict)
