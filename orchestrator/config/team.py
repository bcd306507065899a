"""team_config.json: schema, per-file rules, and the TeamConfig it becomes."""

from __future__ import annotations

import math
import shlex
from collections.abc import Mapping
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Literal, cast

from orchestrator.config.documents import (
    PoseDocument,
    RegistryAuthDocument,
    TeamDocument,
)
from orchestrator.config.model import (
    DEFAULT_MODEL,
    MAX_PLAYERS,
    EcrAuth,
    FieldClass,
    PlayerConfig,
    RegistryAuth,
    StartingPose,
    TeamConfig,
)
from orchestrator.config.problems import Collector, pointer
from orchestrator.config.robot_models import (
    BUILT_IN_MODELS,
    MODEL_MANIFEST,
    check_model,
    is_model_package,
    is_model_path,
)
from orchestrator.config.schema import validate
from orchestrator.errors import Problem

# The robot the GameController marks as goalkeeper unless a robot declares itself goalkeeper
# (RGrt GOALKEEPER): the league GameController's default, player 1.
GOALKEEPER_NUMBER = 1

PoseKey = Literal[
    "halfTimeStartingPose", "reentryStartingPose", "shootoutStartingPose",
    "goalKeeperStartingPose",
]
POSE_KEYS: dict[PoseKey, str] = {
    "halfTimeStartingPose": "half_time_pose",
    "reentryStartingPose": "reentry_pose",
    "shootoutStartingPose": "shootout_pose",
    "goalKeeperStartingPose": "goalkeeper_pose",
}


@dataclass(frozen=True, slots=True)
class FieldBox:
    """The few field numbers the pose rules need (rule book, KidSize / AdultSize)."""

    half_length_m: float
    half_width_m: float
    border_m: float
    penalty_area_length_m: float
    penalty_area_width_m: float


FIELDS: dict[FieldClass, FieldBox] = {
    FieldClass.KID: FieldBox(4.5, 3.0, 1.0, 2.0, 5.0),
    FieldClass.ADULT: FieldBox(7.0, 4.5, 1.0, 3.0, 6.0),
}


def build_team(
    document: Any,
    where: Collector,
    *,
    source: Path,
    field_class: FieldClass | None,
    images_required: bool,
    official: bool = False,
) -> TeamConfig | None:
    """Validate one team document; the TeamConfig when it has no error (problems in ``where``).

    The numbering and pose rules also run on the parts the schema found sound, so one pass
    reports as many problems as possible. ``official``: the team plays an official match, where
    what friendlies allow with a warning (free-form servos, a model of the other size class) is
    an error.
    """
    before = len(where.errors)
    valid = validate("team", document, where)
    broken = [p.pointer for p in where.errors[before:]]
    players_raw = document.get("players") if isinstance(document, dict) else None
    if not isinstance(players_raw, dict) or not all(
        isinstance(k, str) and k.isascii() and k.isdigit() and not k.startswith("0")
        for k in players_raw
    ):
        return None
    _check_name(document.get("name"), where)
    numbers = _check_numbers(players_raw, where, field_class)
    for number in numbers:
        for key in POSE_KEYS:
            at = pointer("players", str(number), key)
            if not any(
                bad == at or at.startswith(bad + "/") or bad.startswith(at) for bad in broken
            ):
                raw_pose = players_raw[str(number)][key]
                _check_pose(raw_pose, at, key, where, field_class)
                if key == "goalKeeperStartingPose" and number == GOALKEEPER_NUMBER:
                    check_goalkeeper_pose(raw_pose, at, where, field_class)
    if not valid:
        return None
    team = cast("TeamDocument", document)  # the schema checked it
    players = [_player(number, team, field_class) for number in numbers]
    players = _resolve_models(players, source, where, field_class=field_class,
                              official=official)
    for player in players:
        _check_command(player, where)
    if not team["players"]:
        where.warn(
            "/players", "the team has no players: it plays without robots (like HLVS Invisibles)"
        )
    if images_required:
        for player in players:
            _check_image(player, where)
    elif players and any(p.image_repository is None or p.docker_tag is None for p in players):
        where.warn(
            "/image",
            "not every player names an image (image + dockerTag): needed to play a match",
            expected='"image" at the top level or in each player, and "dockerTag"',
        )
    if len(where.errors) > before:
        return None
    return TeamConfig(
        source=source,
        name=team["name"],
        players=tuple(players),
        image=team.get("image"),
        registry_auth=_registry_auth(team.get("registry_auth")),
    )


def _resolve_models(
    players: list[PlayerConfig],
    source: Path,
    where: Collector,
    *,
    field_class: FieldClass | None,
    official: bool,
) -> list[PlayerConfig]:
    """Model package paths made absolute (relative to the team file) and checked against the
    rule book, once per folder (``official``: as for an official match); a model that cannot be
    used is an error of its player, what friendlies allow a warning. A model of another size
    class than the game's (``field_class``) is an error in an official match, a warning in a
    friendly."""
    checked: dict[Path, tuple[list[Problem], str | None]] = {}
    out = []
    for player in players:
        at = pointer("players", str(player.number), "model")
        if not is_model_path(player.model):
            _check_size_class(BUILT_IN_CLASS[player.model], at, player.model, where,
                              field_class=field_class, official=official)
            out.append(player)
            continue
        folder = (source.parent / player.model).resolve()
        if not is_model_package(folder):
            where.error(
                at,
                f"no robot model package at {folder}",
                expected=f"a built-in model ({', '.join(BUILT_IN_MODELS)}) "
                f"or a folder with {MODEL_MANIFEST}",
            )
            continue
        if folder not in checked:
            found, measurements = check_model(folder, official=official)
            checked[folder] = (found, measurements.size_class if measurements else None)
        found, size_class = checked[folder]
        for problem in found:
            text = f"{problem.file}: {problem.pointer}: {problem.message}"
            if problem.severity == "error":
                where.error(at, f"the robot model cannot be used: {text}")
            else:
                where.warn(at, f"the robot model is for friendlies only: {text}")
        if size_class is not None:
            _check_size_class(FieldClass(size_class), at, str(folder), where,
                              field_class=field_class, official=official)
        out.append(replace(player, model=str(folder)))
    return out


BUILT_IN_CLASS = {model: size for size, model in DEFAULT_MODEL.items()}
"""The size class of each built-in robot model."""


def _check_size_class(
    size_class: FieldClass,
    at: str,
    model: str,
    where: Collector,
    *,
    field_class: FieldClass | None,
    official: bool,
) -> None:
    """A robot of the other size class than the game's: refused in an official match (the rule
    book's size classes), a warning in a friendly."""
    if field_class is None or size_class is field_class:
        return
    message = (f"{model} is a robot model of the {size_class.value} size class in a game of the "
               f"{field_class.value} size class")
    expected = (f"a model of the {field_class.value} size class: {DEFAULT_MODEL[field_class]}, "
                f'or a model package whose {MODEL_MANIFEST} says "class": "{field_class.value}"')
    if official:
        where.error(at, f"{message} (each size class plays its own robots)", expected=expected)
    else:
        where.warn(at, f"{message}: allowed in friendlies, refused in official matches",
                   expected=expected)


def _player(number: int, document: TeamDocument, field_class: FieldClass | None) -> PlayerConfig:
    raw = document["players"][str(number)]
    return PlayerConfig(
        number=number,
        model=raw.get("model", DEFAULT_MODEL[field_class or FieldClass.KID]),
        proto=raw.get("proto"),
        image_repository=raw.get("image", document.get("image")),
        docker_tag=raw.get("dockerTag"),
        docker_cmd=raw.get("dockerCmd"),
        **{attr: _pose(raw[key]) for key, attr in POSE_KEYS.items()},
    )


def _check_name(name: object, where: Collector) -> None:
    """A team name goes into logs, folder names and web pages: printable text only, no path
    separators (the length is the schema's)."""
    if not isinstance(name, str) or not name:
        return
    bad = sorted({f"U+{ord(c):04X}" for c in name if not c.isprintable() or c in "/\\"})
    if bad or name != name.strip() or name.startswith("."):
        what = ("characters " + ", ".join(bad[:5])) if bad else "leading or trailing blanks or dot"
        where.error("/name", f"the team name has {what}",
                    expected="printable text without / or \\, control or format characters, "
                    "not starting with a dot or blank, at most 64 characters")


def _check_numbers(
    players: Mapping[str, object], where: Collector, field_class: FieldClass | None
) -> list[int]:
    numbers = sorted(int(key) for key in players)
    limit = MAX_PLAYERS[field_class] if field_class else max(MAX_PLAYERS.values())
    for index, number in enumerate(numbers, start=1):
        if number != index:
            where.error(
                pointer("players", str(number)),
                f'player "{number}" without player "{index}"',
                expected=f'players numbered "1".."{len(numbers)}" consecutively',
            )
            return []
    if len(numbers) > limit:
        klass = f"{field_class.name} class" if field_class else "any class"
        where.error(
            pointer("players", str(numbers[limit])),
            f"{len(numbers)} players: too many for {klass}",
            expected=f"at most {limit} players",
        )
        return []
    return numbers


def _pose(raw: PoseDocument) -> StartingPose:
    t = raw["translation"]
    r = raw["rotation"]
    return StartingPose(
        translation=(float(t[0]), float(t[1]), float(t[2])),
        rotation=(float(r[0]), float(r[1]), float(r[2]), float(r[3])),
    )


def _check_pose(
    raw: PoseDocument, at: str, key: str, where: Collector, field_class: FieldClass | None
) -> None:
    x, y, _ = (float(v) for v in raw["translation"])
    ax, ay, az, angle = (float(v) for v in raw["rotation"])
    norm = math.sqrt(ax * ax + ay * ay + az * az)
    if not all(math.isfinite(v) for v in (x, y, ax, ay, az, angle)):
        where.error(at, "not a finite number", expected="finite numbers")
        return
    if norm == 0.0 and angle != 0.0:
        where.error(at + "/rotation", "rotation axis is zero", expected="a non-zero axis")
    elif norm > 0.0 and math.hypot(ax, ay) > 1e-3 * norm and abs(angle) > 1e-6:
        where.warn(
            at + "/rotation",
            "rotation axis is not vertical: only the heading is used",
            expected="an axis [0, 0, +-1]",
        )
    if key == "halfTimeStartingPose" and x >= 0.0:
        where.error(
            at + "/translation/0",
            f"x = {x:g} is not on the team's own half",
            expected="x < 0 (poses are written as if the team played on the left half)",
        )
    if field_class is None:
        return
    box = FIELDS[field_class]
    x_max, y_max = box.half_length_m + box.border_m, box.half_width_m + box.border_m
    if abs(x) > x_max or abs(y) > y_max:
        where.error(
            at + "/translation",
            f"({x:g}, {y:g}) is off the turf of the {field_class.name} field",
            expected=f"|x| <= {x_max:g} and |y| <= {y_max:g}",
        )


def check_goalkeeper_pose(
    raw: PoseDocument, at: str, where: Collector, field_class: FieldClass | None
) -> None:
    """The one goalkeeper pose rule, the same for an upload (no field class yet), ``hlvs check``
    and a match or pre-flight (with its class); for the goalkeeper's pose only.

    The league's referee (``referee.py``) uses ``goalKeeperStartingPose`` only for the robot the
    GameController marks as goalkeeper, to place it in a penalty shoot-out, and refuses no team
    file for it: a pose away from the own goal is a warning (the shoot-out's goalkeeper rule
    then applies: on or behind its goal line between the posts); the other players' goalkeeper
    poses are not looked at (a robot that declares itself goalkeeper gets its own)."""
    x, y = (float(v) for v in raw["translation"][:2])
    if not (math.isfinite(x) and math.isfinite(y)):
        return  # _check_pose reports it
    if field_class is None:
        x_limit, y_limit, wanted = 0.0, math.inf, "x < 0, near the own goal line"
        near = x < x_limit
    else:
        box = FIELDS[field_class]
        x_limit = -(box.half_length_m - box.penalty_area_length_m)
        y_limit = box.penalty_area_width_m / 2
        wanted = f"inside the own penalty area: x <= {x_limit:g} and |y| <= {y_limit:g}"
        near = x <= x_limit and abs(y) <= y_limit
    if not near:
        where.warn(
            at + "/translation",
            f"({x:g}, {y:g}): the goalkeeper would start a penalty shoot-out away from its "
            "own goal (league referee: the shoot-out goalkeeper must stay on or behind its "
            "goal line between the posts)",
            expected=wanted,
        )


def _check_command(player: PlayerConfig, where: Collector) -> None:
    """``dockerCmd`` splits like a shell line (it is split so when the robot starts)."""
    if player.docker_cmd is None:
        return
    try:
        shlex.split(player.docker_cmd)
    except ValueError as exc:
        where.error(
            pointer("players", str(player.number), "dockerCmd"),
            f"cannot be split into arguments: {exc}",
            expected="a command line with every quote closed, e.g. \"python3 /robot/main.py\"",
        )


def _check_image(player: PlayerConfig, where: Collector) -> None:
    at = pointer("players", str(player.number))
    if player.image_repository is None:
        where.error(
            at + "/image",
            "no image named for this player",
            expected='"image" at the top level or in the player, and "dockerTag"',
        )
    elif player.docker_tag is None:
        where.error(
            at + "/dockerTag", "no dockerTag for this player", expected="a tag, e.g. latest"
        )


def _registry_auth(raw: RegistryAuthDocument | None) -> RegistryAuth | None:
    if raw is None:
        return None
    ecr = raw.get("ecr")
    return RegistryAuth(
        username=raw.get("username"),
        password=raw.get("password"),
        password_env=raw.get("password_env"),
        ecr=(
            EcrAuth(
                region=ecr["region"],
                access_id=ecr.get("access_id"),
                access_secret=ecr.get("access_secret"),
            )
            if ecr is not None
            else None
        ),
    )
