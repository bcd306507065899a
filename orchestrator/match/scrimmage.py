"""``hlvs scrimmage``: a short match between two teams of stub robots, from generated files.

The files (game.json, team_red.json, team_blue.json) are written into the output folder and then
played exactly like ``hlvs match`` would play them, so a team can rerun or edit them.

Defaults make a short game a newcomer can watch in two to three minutes: one striker per team,
lockstep stepping and the timing of :data:`contracts.timing.SCRIMMAGE` (two halves of 40 s of game
clock with a READY of 20 s: READY and SET before a half's kick-off stop the clock, as the
league's GameController does, so a half lasts about 65 s of simulated time; 3 s before the first
READY and 1 s at half time); on the adult field :data:`contracts.timing.ADULT_SCRIMMAGE` (60 s
halves, 30 s READY: the field is half again as long). A half shorter than the minimum of play is
refused (:func:`quick_ready`); official matches keep the rules' timings (45 s READY, 10 min
halves).
"""

from __future__ import annotations

import json
import logging
import uuid
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

from contracts import (
    ADULT_FIELD,
    ADULT_SCRIMMAGE,
    KID_FIELD,
    MIN_PLAYING_S,
    SCRIMMAGE,
    FieldClass,
    FieldGeometry,
    SteppingMode,
    TimingError,
    fit_ready,
)
from orchestrator.config.documents import GameDocument, PlayerDocument, PoseDocument, TeamDocument
from orchestrator.config.game import default_real_time_factor
from orchestrator.config.model import DEFAULT_MODEL, MAX_PLAYERS
from orchestrator.config.robot_models import MODEL_MANIFEST, is_model_path
from orchestrator.errors import ConfigError, Problem

log = logging.getLogger(__name__)

TIMING = {FieldClass.KID: SCRIMMAGE, FieldClass.ADULT: ADULT_SCRIMMAGE}
"""A scrimmage's timing by field (its halves and READY unless the request names them)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class ScrimmageRequest:
    """What the generated files depend on. ``half_duration_s`` and ``ready_duration_s`` None:
    the field's scrimmage timing (:data:`TIMING`), READY fitted to the half; ``minimum_play_s``
    0: a match not meant to play; images None play the project's stub image; models None the
    class's built-in model; ``field_class`` None: the size class of the built-in models named
    (adult when a team plays ``adult-default``), else kid."""

    players: int
    seed: int
    wait_before_ready_s: float
    grace_s: float
    half_duration_s: float | None = None
    ready_duration_s: float | None = None
    stepping: SteppingMode = "lockstep"
    gpu: str = "auto"
    red_image: str | None = None
    blue_image: str | None = None
    match_id: str | None = None
    robot_command: str | None = None
    red_model: str | None = None
    blue_model: str | None = None
    minimum_play_s: float = MIN_PLAYING_S
    field_class: FieldClass | None = None

    @property
    def field(self) -> FieldClass:
        """The field the scrimmage is played on (``field_class``, else the models')."""
        if self.field_class is not None:
            return self.field_class
        adult = DEFAULT_MODEL[FieldClass.ADULT]
        return FieldClass.ADULT if adult in (self.red_model, self.blue_model) else FieldClass.KID

    @property
    def half_s(self) -> float:
        """Simulated seconds of game clock per half (``half_duration_s``, else the field's)."""
        if self.half_duration_s is not None:
            return self.half_duration_s
        return TIMING[self.field].half_duration_s

    @classmethod
    def from_options(cls, options: ScrimmageOptions) -> ScrimmageRequest:
        """The request of ``hlvs scrimmage``'s parsed options (or any object with their
        attributes; ``ready_duration``, ``stepping``, ``gpu`` and the models when present)."""
        return cls(
            players=options.players, seed=options.seed,
            half_duration_s=getattr(options, "half_duration", None),
            wait_before_ready_s=options.wait_before_ready, grace_s=options.grace,
            ready_duration_s=getattr(options, "ready_duration", None),
            stepping=getattr(options, "stepping", None) or "lockstep",
            gpu=getattr(options, "gpu", None) or "auto",
            red_image=options.red_image, blue_image=options.blue_image,
            match_id=options.match_id, robot_command=options.robot_command,
            red_model=getattr(options, "red_model", None),
            blue_model=getattr(options, "blue_model", None),
            minimum_play_s=MIN_PLAYING_S if getattr(options, "minimum_play", None) is None
            else options.minimum_play,  # type: ignore[attr-defined]
            field_class=FieldClass(options.field_class)  # type: ignore[attr-defined]
            if getattr(options, "field_class", None) else None,
        )


class ScrimmageOptions(Protocol):
    """``hlvs scrimmage``'s parsed options (:mod:`orchestrator.scrimmage_options`), as
    :meth:`ScrimmageRequest.from_options` reads them."""

    players: int
    seed: int
    wait_before_ready: float
    grace: float
    red_image: str | None
    blue_image: str | None
    match_id: str | None
    robot_command: str | None


# Who plays, by team size: one striker alone; then a goalie; players 3 and 4 defend from spots
# in the own half (several strikers chasing one ball mostly knock each other over).
ROLES = {
    1: ("striker",),
    2: ("goalie", "striker"),
    3: ("goalie", "striker", "defender-3"),
    4: ("goalie", "striker", "defender-3", "defender-4"),
}


@dataclass(frozen=True, slots=True)
class Spots:
    """Where a field class's stub players stand, as if playing on the left (x < 0).

    ``start``: on the own touch line facing the field (the striker near the halfway line, so
    that it reaches its kick-off spot within the scrimmage's READY); ``homes``: the defenders'
    spots in the own half; ``height_m``: the poses' z; ``goalkeeper_x_m``, ``shootout_x_m``:
    the goal line pose and the penalty shoot-out's."""

    start: dict[str, tuple[float, float, float]]
    homes: dict[str, tuple[float, float]]
    height_m: float
    goalkeeper_x_m: float
    shootout_x_m: float


def _spots(field: FieldGeometry, height_m: float) -> Spots:
    """The kid spots (measured with the stub) scaled to ``field``: x with the half length, y
    with the half width, the touch line pose just outside the line."""
    sx = field.half_length_m / KID_FIELD.half_length_m
    sy = field.half_width_m / KID_FIELD.half_width_m
    touch = round(-(field.half_width_m + 0.1), 2)
    return Spots(
        start={
            "goalie": (round(-4.0 * sx, 2), touch, 1.57),
            "striker": (round(-(field.centre_circle_radius_m + 0.05), 2), touch, 1.57),
            "defender-3": (round(-2.0 * sx, 2), touch, 1.57),
            "defender-4": (round(-3.0 * sx, 2), touch, 1.57),
        },
        homes={"defender-3": (round(-2.3 * sx, 2), sy), "defender-4": (round(-2.3 * sx, 2), -sy)},
        height_m=height_m,
        goalkeeper_x_m=round(-(field.half_length_m - 0.05), 2),
        shootout_x_m=round(field.half_length_m - field.penalty_mark_distance_m - 0.4, 2),
    )


SPOTS = {FieldClass.KID: _spots(KID_FIELD, 0.43), FieldClass.ADULT: _spots(ADULT_FIELD, 0.9)}


def _pose(x: float, y: float, yaw: float, z: float) -> PoseDocument:
    return {"translation": [x, y, z], "rotation": [0, 0, 1, yaw]}


def team_file(name: str, image: str, players: int, *, command: str | None = None,
              goalie_first: bool = False, model: str | None = None,
              field_class: FieldClass = FieldClass.KID) -> TeamDocument:
    """A stub team of ``players`` with the roles of :data:`ROLES` on a ``field_class`` field;
    ``goalie_first`` makes a lone player a goalie (an opponent that only defends); ``model`` the
    robot model of every player (a built-in name or a model package folder; default: the
    class's built-in)."""
    repository, _, tag = image.rpartition(":") if ":" in image.split("/")[-1] else (image, "", "")
    entries: dict[str, PlayerDocument] = {}
    roles = ROLES[players]
    if goalie_first and roles[0] != "goalie":
        roles = ("goalie", *roles[1:])
    spots = SPOTS[field_class]
    # the stub drives the built-in model it is told (gait, kick and get-up are per model; a
    # team's package is not one it knows) on the scrimmage's field
    driven = f" --field-class {field_class.value}"
    if model is None or not is_model_path(model):
        driven = f" --model {model or DEFAULT_MODEL[field_class]}{driven}"
    z = spots.height_m
    for n, slot in enumerate(roles, start=1):
        x, y, yaw = spots.start[slot]
        role = slot.split("-")[0]
        extra = " --home {:g} {:g}".format(*spots.homes[slot]) if slot in spots.homes else ""
        extra += driven
        entries[str(n)] = {
            # The stub cannot see where it was placed: its dockerCmd tells it (team-file frame).
            "dockerCmd": command or f"{role} --start-pose {x:g} {y:g} {yaw:g}{extra}",
            "halfTimeStartingPose": _pose(x, y, yaw, z),
            "reentryStartingPose": _pose(x, y, yaw, z),
            "shootoutStartingPose": _pose(spots.shootout_x_m, 0.0, 0.0, z),
            "goalKeeperStartingPose": _pose(spots.goalkeeper_x_m, 0.0, 0.0, z),
        }
        if tag:
            entries[str(n)]["dockerTag"] = tag
        if model:
            entries[str(n)]["model"] = model
    return {"name": name, "image": repository or image, "players": entries}


def quick_ready(half_duration_s: float, ready_duration_s: float | None,
                minimum_play_s: float = MIN_PLAYING_S, *,
                default_s: float = SCRIMMAGE.ready_duration_s) -> float:
    """The READY of a quick test (:mod:`contracts.timing`): ``default_s`` unless given (the
    clock stands still in READY, so it never eats into the half).

    Raises :class:`~orchestrator.errors.ConfigError` (at ``/timing/half_duration_s``) when the
    half is shorter than the minimum of play."""
    ready = default_s if ready_duration_s is None else ready_duration_s
    try:
        fitted, warning = fit_ready(half_duration_s, ready, minimum_s=minimum_play_s)
    except TimingError as exc:
        raise ConfigError([Problem(file="game.json", pointer="/timing/half_duration_s",
                                   message=str(exc),
                                   expected=f"a half of at least {minimum_play_s:g} s (or "
                                   "--minimum-play 0 for a match not meant to play)")]) from exc
    if warning is not None:
        log.warning("%s", warning)
    return fitted


def game_file(request: ScrimmageRequest, match_id: str) -> GameDocument:
    """A quick test's game.json; READY fitted to the half by :func:`quick_ready`."""
    players = request.players
    minimum = request.minimum_play_s
    ready = quick_ready(request.half_s, request.ready_duration_s, minimum,
                        default_s=TIMING[request.field].ready_duration_s)
    return {
        "type": "NORMAL",
        "class": "ADULT" if request.field is FieldClass.ADULT else "KID",
        "host": "127.0.0.1",
        "maximum_real_time_factor": default_real_time_factor(request.stepping),
        "side_left": "red",
        "kickoff": "red",
        "match_id": match_id,
        "seed": request.seed,
        "stepping": request.stepping,
        "gpu": request.gpu,
        "lockstep_deadline_ms": 200,
        "lockstep_time_bank_ms": 10000,
        "red": {"id": 1, "config": "team_red.json", "hosts": ["127.0.0.1"],
                "ports": [10000 + n for n in range(1, players + 1)]},
        "blue": {"id": 2, "config": "team_blue.json", "hosts": ["127.0.0.1"],
                 "ports": [10020 + n for n in range(1, players + 1)]},
        "timing": {
            "half_duration_s": request.half_s,
            "ready_duration_s": ready,
            "minimum_play_s": minimum,
            "wait_before_first_ready_s": request.wait_before_ready_s,
            "half_time_break_s": SCRIMMAGE.half_time_break_s,
            "grace_period_s": request.grace_s,
        },
        "limits": {"cpus": 1, "memory_gb": 1, "pids": 256, "log_folder_gb": 1},
    }


def stub_model_problem(model: str | None) -> str | None:
    """Why the stub robot cannot drive ``model`` (a model package whose motor names are not the
    built-in robot's, which the stub commands), or None."""
    if model is None or not is_model_path(model):
        return None
    from robot import MOTOR_NAMES

    manifest = Path(model) / MODEL_MANIFEST
    try:
        motors = {m["name"] for m in json.loads(manifest.read_text(encoding="utf-8"))["motors"]}
    except (OSError, ValueError, KeyError, TypeError):
        return None  # the team file's check reports a broken package with its field
    missing = [name for name in MOTOR_NAMES if name not in motors]
    if not missing:
        return None
    return (f"the stub robot commands the built-in robot's motors ({', '.join(missing[:4])}, "
            f"...), which {manifest} does not name (it has {', '.join(sorted(motors)[:4])}, "
            "...): every command is refused and the robot stands still all match. Give a "
            "robot image that drives this model (--red-image / --blue-image)")


def write_files(request: ScrimmageRequest, folder: Path, *, stub_image: str | None = None
                ) -> Path:
    """Write game.json and the two team files into ``folder``; returns the game.json path.

    A stub robot given a team model with other motor names would stand still: said loudly (a
    WARNING, shown whatever the log level). More players than the field's class allows is a
    :class:`~orchestrator.errors.ConfigError` naming ``--players``."""
    most = MAX_PLAYERS[request.field]
    if request.players > most:
        raise ConfigError([Problem(
            file="hlvs scrimmage", pointer="--players",
            message=f"{request.players} players per team on the {request.field.value} field",
            expected=f"at most {most}, as the {request.field.value}-size rules allow")])
    for color, image, model in (("red", request.red_image, request.red_model),
                                ("blue", request.blue_image, request.blue_model)):
        problem = stub_model_problem(model) if image is None else None
        if problem is not None:
            log.warning("%s robots: %s", color, problem)
    if request.red_image is None or request.blue_image is None:
        if stub_image is None:
            from orchestrator.project_images import project_image

            stub_image = project_image("stub")
    red_image = request.red_image or stub_image
    blue_image = request.blue_image or stub_image
    assert red_image is not None and blue_image is not None
    match_id = request.match_id or f"scrimmage-{uuid.uuid4().hex[:6]}"
    folder.mkdir(parents=True, exist_ok=True)
    files = {
        "game.json": game_file(request, match_id),
        "team_red.json": team_file("Stub Red", red_image, request.players,
                                   command=request.robot_command, model=request.red_model,
                                   field_class=request.field),
        "team_blue.json": team_file("Stub Blue", blue_image, request.players,
                                    command=request.robot_command, model=request.blue_model,
                                    field_class=request.field),
    }
    for name, content in files.items():
        (folder / name).write_text(json.dumps(content, indent=2) + "\n", encoding="utf-8")
    return folder / "game.json"


__all__ = ["SPOTS", "TIMING", "ScrimmageOptions", "ScrimmageRequest", "game_file", "quick_ready",
           "stub_model_problem", "team_file", "write_files"]
