"""Validating game.json with its team files, or one team file, into frozen dataclasses.

``parse_game`` and ``parse_team`` take a document (the parsed JSON) and the name of its source;
files are one way to get a document: ``load_*`` read the file and parse it. Both raise one
:class:`ConfigError` listing every problem found (warnings included); ``check_*`` return the
problems instead, for ``hlvs check``.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from orchestrator.config.game import build_game, locate_team_config
from orchestrator.config.jsonfile import read_json
from orchestrator.config.model import (
    COLORS,
    Color,
    FieldClass,
    GameConfig,
    LoadedGame,
    LoadedTeam,
    TeamConfig,
)
from orchestrator.config.problems import Collector, pointer, raise_if_errors
from orchestrator.config.team import build_team
from orchestrator.errors import ConfigError, Problem
from orchestrator.image_origin import local_name_reason


def load_game(path: str | Path, *, images_required: bool = False) -> LoadedGame:
    """game.json and the two team files it references, validated: the file read and given to
    :func:`parse_game` (problems name the file).

    Args:
        path: the game.json file; team ``config`` paths are relative to its folder.
        images_required: every player must name an image (``image`` + ``dockerTag``), as a
            match needs; otherwise a missing image is a warning.

    Returns:
        The game, both teams, and the warnings (the caller shows them).

    Raises:
        ConfigError: with every problem found in game.json and in both team files.
    """
    path = Path(path)
    return parse_game(read_json(path), source=path, images_required=images_required)


def parse_game(
    document: object,
    *,
    source: str | Path,
    teams: Mapping[Color, TeamConfig] | None = None,
    images_required: bool = False,
) -> LoadedGame:
    """A game.json document with its two teams, validated.

    Args:
        document: the parsed JSON of game.json.
        source: where the document comes from: names it in problems; relative paths in it
            (team ``config``, ``credentials``) resolve against its folder.
        teams: both teams, already parsed (:func:`parse_team` with the game's field class);
            without, each is read from the file its ``config`` names.
        images_required: as in :func:`load_game`.

    Raises:
        ConfigError: with every problem found.
    """
    loaded, problems = _game_document(document, Path(source), teams=teams,
                                      images_required=images_required)
    raise_if_errors(problems)
    assert loaded is not None
    return loaded


def parse_team(
    document: object,
    *,
    source: str | Path,
    field_class: FieldClass | None = None,
    images_required: bool = False,
) -> LoadedTeam:
    """A team_config.json document, validated (pose rules for ``field_class`` when given);
    ``source`` names it in problems and relative model folders resolve next to it."""
    team, problems = check_team_document(document, source=source, field_class=field_class,
                                         images_required=images_required)
    raise_if_errors(problems)
    assert team is not None
    return LoadedTeam(team=team, warnings=tuple(problems))


def load_team(
    path: str | Path, *, field_class: FieldClass | None = None, images_required: bool = False
) -> LoadedTeam:
    """One team_config.json file, validated: read and given to :func:`parse_team`."""
    path = Path(path)
    return parse_team(read_json(path), source=path, field_class=field_class,
                      images_required=images_required)


def check_team_document(
    document: object,
    *,
    source: str | Path,
    field_class: FieldClass | None = None,
    images_required: bool = False,
    official: bool = False,
) -> tuple[TeamConfig | None, list[Problem]]:
    """A team document's TeamConfig (None when it has an error) and every problem of it (the
    one team validation: :func:`parse_team` raises its errors, files are read and given here);
    ``official``: as the team of an official match (see :func:`build_team`)."""
    where = Collector(str(Path(source)))
    team = build_team(
        document,
        where,
        source=Path(source),
        field_class=field_class,
        images_required=images_required,
        official=official,
    )
    return team, where.problems


def check_game(path: str | Path, *, images_required: bool = False) -> list[Problem]:
    """Every problem (errors and warnings) in game.json and the team files it references."""
    path = Path(path)
    document, problems = _read(path)
    if problems:
        return problems
    return _game_document(document, path, teams=None, images_required=images_required)[1]


def check_team(
    path: str | Path,
    *,
    field_class: FieldClass | None = None,
    images_required: bool = False,
    official: bool = False,
) -> list[Problem]:
    """Every problem (errors and warnings) in one team_config.json file; ``official``: as the
    team of an official match."""
    return _team_file(Path(path), field_class=field_class, images_required=images_required,
                      official=official)[1]


def _read(path: Path) -> tuple[object, list[Problem]]:
    """The JSON document of a file, or the problem that it cannot be read or parsed."""
    try:
        return read_json(path), []
    except ConfigError as exc:
        return None, exc.problems


def _game_document(
    document: object, path: Path, *, teams: Mapping[Color, TeamConfig] | None,
    images_required: bool,
) -> tuple[LoadedGame | None, list[Problem]]:
    where = Collector(str(path))
    game = build_game(document, where, source=path)
    problems = list(where.problems)
    if teams is not None:
        for color in COLORS:
            if game is not None:
                problems.extend(_cross_checks(game, color, teams[color]))
        return _assembled(game, teams.get("red"), teams.get("blue"), problems)
    found: dict[str, TeamConfig | None] = {}
    field_class = _field_class(document)
    official = isinstance(document, dict) and document.get("official") is True
    for color in COLORS:
        located = _team_path(document, color, path.parent)
        if located is None:
            found[color] = None
            continue
        config, tried = located
        if not config.is_file():
            what = "is a directory" if config.is_dir() else "file not found"
            places = " nor ".join(str(p) for p in tried)
            problems.append(
                Problem(
                    str(path),
                    pointer(color, "config"),
                    f"{what}: neither {places}" if len(tried) > 1 else f"{what}: {config}",
                    expected="a team_config.json path relative to this file "
                    "or to the current directory",
                )
            )
            found[color] = None
            continue
        if config != tried[0]:
            problems.append(
                Problem(
                    str(path),
                    pointer(color, "config"),
                    f"not next to this file ({tried[0]}); found in the current directory: "
                    f"{config}",
                    expected="a team_config.json path relative to this file",
                    severity="warning",
                )
            )
        team, team_problems = _team_file(
            config, field_class=field_class, images_required=images_required, official=official
        )
        problems.extend(team_problems)
        found[color] = team
        if team is not None and game is not None:
            problems.extend(_cross_checks(game, color, team))
    return _assembled(game, found.get("red"), found.get("blue"), problems)


def _assembled(
    game: GameConfig | None, red: TeamConfig | None, blue: TeamConfig | None,
    problems: list[Problem],
) -> tuple[LoadedGame | None, list[Problem]]:
    if game is None or red is None or blue is None or _has_errors(problems):
        return None, problems
    warnings = tuple(p for p in problems if p.severity == "warning")
    return LoadedGame(game=game, red=red, blue=blue, warnings=warnings), problems


def _team_file(
    path: Path, *, field_class: FieldClass | None, images_required: bool, official: bool = False
) -> tuple[TeamConfig | None, list[Problem]]:
    document, problems = _read(path)
    if problems:
        return None, problems
    return check_team_document(document, source=path, field_class=field_class,
                               images_required=images_required, official=official)


def _cross_checks(game: GameConfig, color: str, team: TeamConfig) -> list[Problem]:
    """Rules that need game.json and a team file together."""
    ref = game.red if color == "red" else game.blue
    where = Collector(str(game.source))
    if len(team.players) > len(ref.ports):
        where.error(
            pointer(color, "ports"),
            f"{len(ref.ports)} ports for the {len(team.players)} players of {team.source}",
            expected="one port per player",
        )
    problems = list(where.problems)
    if game.registry_images:
        problems.extend(_registry_images(team))
    return problems


def _registry_images(team: TeamConfig) -> list[Problem]:
    """Where the game takes team images from a registry only, each must name one (one problem
    per field: the team's ``image`` or a player's own)."""
    where = Collector(str(team.source))
    found: dict[str, str] = {}
    for player in team.players:
        image = player.image
        reason = local_name_reason(image) if image else None
        if reason is None:
            continue
        own = player.image_repository != team.image
        found.setdefault(pointer("players", str(player.number), "image") if own else "/image",
                         reason)
    for at, reason in found.items():
        where.error(at, reason, expected="registry/path/name (game.json sets registry_images, "
                    "or official)")
    return where.problems


def _team_path(
    document: object, color: str, base: Path
) -> tuple[Path, tuple[Path, ...]] | None:
    """The team file of ``color`` and every place looked at (see locate_team_config)."""
    if not isinstance(document, dict):
        return None
    side = document.get(color)
    if not isinstance(side, dict) or not isinstance(side.get("config"), str):
        return None
    config: str = side["config"]
    return locate_team_config(config, base) if config else None


def _field_class(document: object) -> FieldClass | None:
    if isinstance(document, dict):
        value = document.get("class")
        if value == "KID":
            return FieldClass.KID
        if value == "ADULT":
            return FieldClass.ADULT
    return None


def _has_errors(problems: list[Problem]) -> bool:
    return any(p.severity == "error" for p in problems)
