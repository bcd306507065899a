"""Broken configurations as data: each one must be rejected with the right file and pointer."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import pytest

from orchestrator.config import check_game, load_game
from orchestrator.errors import ConfigError
from tests.unit.config.conftest import GameFiles

Mutation = Callable[[GameFiles], None]


def _walk(files: GameFiles, doc: str, path: tuple[Any, ...]) -> tuple[Any, Any]:
    node = getattr(files, doc)
    for key in path[:-1]:
        node = node[key]
    return node, path[-1]


def put(doc: str, *path: Any, value: Any) -> Mutation:
    def apply(files: GameFiles) -> None:
        node, last = _walk(files, doc, path)
        node[last] = value

    return apply


def drop(doc: str, *path: Any) -> Mutation:
    def apply(files: GameFiles) -> None:
        node, last = _walk(files, doc, path)
        del node[last]

    return apply


def rename(doc: str, *path: Any, to: str) -> Mutation:
    def apply(files: GameFiles) -> None:
        node, last = _walk(files, doc, path)
        node[to] = node.pop(last)

    return apply


def raw(name: str, data: bytes) -> Mutation:
    def apply(files: GameFiles) -> None:
        files.raw[name] = data

    return apply


def both(*mutations: Mutation) -> Mutation:
    def apply(files: GameFiles) -> None:
        for mutation in mutations:
            mutation(files)

    return apply


def make_dir(name: str) -> Mutation:
    def apply(files: GameFiles) -> None:
        (files.folder / name).mkdir()

    return apply


@dataclass(frozen=True)
class Case:
    id: str
    mutate: Mutation
    file: str
    pointer: str
    fragment: str  # in the message or in "expected"
    suggestion: str = ""
    args: tuple[str, ...] = field(default=())


HALF = "halfTimeStartingPose"

CASES = [
    # game.json: fields
    Case("missing-type", drop("game", "type"), "game.json", "/type", "required"),
    Case(
        "rtf-string",
        put("game", "maximum_real_time_factor", value="fast"),
        "game.json",
        "/maximum_real_time_factor",
        "a number",
    ),
    Case(
        "type-typo",
        put("game", "type", value="NORMALL"),
        "game.json",
        "/type",
        "NORMAL",
        suggestion="NORMAL",
    ),
    Case(
        "class-lowercase",
        put("game", "class", value="kid"),
        "game.json",
        "/class",
        "KID",
        suggestion="KID",
    ),
    Case(
        "unknown-kick_off",
        rename("game", "type", to="kick_off"),
        "game.json",
        "/kick_off",
        "unknown field",
    ),
    Case(
        "misspelt-kickoff",
        put("game", "kickof", value="red"),
        "game.json",
        "/kickof",
        "unknown field",
        suggestion="kickoff",
    ),
    Case(
        "misspelt-side_left",
        put("game", "side-left", value="red"),
        "game.json",
        "/side-left",
        "unknown field",
        suggestion="side_left",
    ),
    Case("host-not-ipv4", put("game", "host", value="256.1.1.1"), "game.json", "/host", "IPv4"),
    Case(
        "hosts-name",
        put("game", "red", "hosts", value=["localhost"]),
        "game.json",
        "/red/hosts/0",
        "IPv4",
    ),
    Case(
        "port-twice-in-team",
        put("game", "red", "ports", 1, value=10001),
        "game.json",
        "/red/ports/1",
        "already used",
    ),
    Case(
        "port-twice-across-teams",
        put("game", "blue", "ports", 0, value=10003),
        "game.json",
        "/blue/ports/0",
        "/red/ports/2",
    ),
    Case("same-team-ids", put("game", "blue", "id", value=8), "game.json", "/blue/id", "red team"),
    Case("id-not-number", put("game", "red", "id", value="abc"), "game.json", "/red/id", "integer"),
    Case("id-too-large", put("game", "red", "id", value=300), "game.json", "/red/id", "0-255"),
    Case(
        "port-out-of-range",
        put("game", "red", "ports", 0, value=70000),
        "game.json",
        "/red/ports/0",
        "65535",
    ),
    Case(
        "fewer-ports-than-players",
        put("game", "red", "ports", value=[10001, 10002]),
        "game.json",
        "/red/ports",
        "one port per player",
    ),
    Case(
        "team-file-missing",
        put("game", "red", "config", value="nowhere.json"),
        "game.json",
        "/red/config",
        "file not found",
    ),
    Case(
        "team-file-directory",
        both(make_dir("teams"), put("game", "blue", "config", value="teams")),
        "game.json",
        "/blue/config",
        "directory",
    ),
    Case(
        "credentials-missing",
        put("game", "red", "credentials", value="creds.json"),
        "game.json",
        "/red/credentials",
        "file not found",
    ),
    Case(
        "record-avi",
        put("game", "record_simulation", value="out.avi"),
        "game.json",
        "/record_simulation",
        ".mp4",
    ),
    Case(
        "side-left-value",
        put("game", "side_left", value="left"),
        "game.json",
        "/side_left",
        '"random"',
    ),
    Case(
        "stepping-typo",
        put("game", "stepping", value="lock-step"),
        "game.json",
        "/stepping",
        "async",
        suggestion="lockstep",
    ),
    Case(
        "physics-dt", put("game", "physics_dt_s", value=0.003), "game.json", "/physics_dt_s", "8 ms"
    ),
    Case(
        "limits-typo",
        put("game", "limits", value={"memory": 8}),
        "game.json",
        "/limits/memory",
        "unknown field",
        suggestion="memory_gb",
    ),
    Case(
        "timing-negative",
        put("game", "timing", value={"half_duration_s": -1}),
        "game.json",
        "/timing/half_duration_s",
        "> 0",
    ),
    Case(
        "gc-args-bad-duration",
        put("game", "game_controller_extra_args", value=["--halftimeduration", "abc"]),
        "game.json",
        "/game_controller_extra_args/1",
        "invalid duration",
    ),
    Case(
        "gc-args-conflict",
        both(
            put("game", "game_controller_extra_args", value=["--halftimeduration", "120"]),
            put("game", "timing", value={"half_duration_s": 300}),
        ),
        "game.json",
        "/timing/half_duration_s",
        "conflicts",
    ),
    Case(
        "match-id-chars",
        put("game", "match_id", value="bad id!"),
        "game.json",
        "/match_id",
        "letters",
    ),
    Case("seed-negative", put("game", "seed", value=-1), "game.json", "/seed", ">= 0"),
    Case("red-without-ports", drop("game", "red", "ports"), "game.json", "/red/ports", "required"),
    Case("blue-missing", drop("game", "blue"), "game.json", "/blue", "required"),
    Case("game-is-array", raw("game.json", b"[1, 2, 3]"), "game.json", "/", "an object"),
    # team files
    Case("team-without-name", drop("red", "name"), "team_red.json", "/name", "required"),
    Case(
        "five-players-kid",
        put("red", "players", "5", value=None),
        "team_red.json",
        "/players/5",
        "at most 4",
    ),
    Case(
        "player-gap", drop("blue", "players", "2"), "team_blue.json", "/players/3", "consecutively"
    ),
    Case(
        "player-key-word",
        rename("red", "players", "4", to="four"),
        "team_red.json",
        "/players/four",
        '"1".."N"',
    ),
    Case(
        "half-time-pose-wrong-half",
        put("red", "players", "2", HALF, "translation", 0, value=1.0),
        "team_red.json",
        f"/players/2/{HALF}/translation/0",
        "own half",
    ),
    Case(
        "pose-off-turf",
        put("red", "players", "1", HALF, "translation", 1, value=9.0),
        "team_red.json",
        f"/players/1/{HALF}/translation",
        "off the turf",
    ),
    Case(
        "translation-two-items",
        put("red", "players", "1", HALF, "translation", value=[-1.0, 2.0]),
        "team_red.json",
        f"/players/1/{HALF}/translation",
        "3 numbers",
    ),
    Case(
        "rotation-string",
        put("red", "players", "1", HALF, "rotation", 3, value="90deg"),
        "team_red.json",
        f"/players/1/{HALF}/rotation/3",
        "a number",
    ),
    Case(
        "rotation-zero-axis",
        put("red", "players", "1", HALF, "rotation", value=[0, 0, 0, 1.0]),
        "team_red.json",
        f"/players/1/{HALF}/rotation",
        "axis",
    ),
    Case(
        "misspelt-dockerTag",
        rename("red", "players", "1", "dockerTag", to="dockerTAG"),
        "team_red.json",
        "/players/1/dockerTAG",
        "unknown field",
        suggestion="dockerTag",
    ),
    Case(
        "misspelt-pose-key",
        rename("blue", "players", "2", HALF, to="halfTimeStartPose"),
        "team_blue.json",
        "/players/2/halfTimeStartPose",
        "unknown field",
        suggestion=HALF,
    ),
    Case(
        "registry-auth-incomplete",
        put("red", "registry_auth", value={"username": "x"}),
        "team_red.json",
        "/registry_auth",
        "password_env",
    ),
    Case(
        "image-with-spaces",
        put("red", "image", value="Bad Image"),
        "team_red.json",
        "/image",
        "repository",
    ),
    Case(
        "docker-tag-space",
        put("red", "players", "1", "dockerTag", value="has space"),
        "team_red.json",
        "/players/1/dockerTag",
        "Docker tag",
    ),
    Case(
        "players-list", put("blue", "players", value=[]), "team_blue.json", "/players", "an object"
    ),
    Case(
        "four-players-adult",
        put("game", "class", value="ADULT"),
        "team_red.json",
        "/players/4",
        "at most 3",
    ),
    Case(
        "image-required",
        drop("red", "image"),
        "team_red.json",
        "/players/1/image",
        "no image",
        args=("--require-images",),
    ),
    # files that are not JSON documents
    Case(
        "team-invalid-json",
        raw("team_red.json", b'{\n  "name": "x",\n  "players": {,}\n}'),
        "team_red.json",
        "/",
        "line 3 column 15",
    ),
    Case("team-empty", raw("team_blue.json", b""), "team_blue.json", "/", "empty"),
    Case(
        "game-binary",
        raw("game.json", b"\x7fELF\x02\x01\x01\x00\x00\x00"),
        "game.json",
        "/",
        "binary",
    ),
    Case("game-nan", raw("game.json", b'{"type": NaN}'), "game.json", "/", "finite"),
    Case(
        "team-latin1",
        raw("team_red.json", '{"name": "Équipe"}'.encode("latin-1")),
        "team_red.json",
        "/",
        "UTF-8",
    ),
]


def _write(files: GameFiles, case: Case) -> Path:
    files.raw = {}
    case.mutate(files)
    # JSON null marks a player to be filled with a copy of player 1
    for team in (files.red, files.blue):
        for key, value in (
            list(team.get("players", {}).items()) if isinstance(team.get("players"), dict) else []
        ):
            if value is None:
                team["players"][key] = team["players"]["1"]
    path = files.write()
    for name, data in files.raw.items():
        (files.folder / name).write_bytes(data)
    return path


def test_there_are_at_least_forty_cases() -> None:
    assert len(CASES) >= 40
    assert len({c.id for c in CASES}) == len(CASES)


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_broken_config_is_rejected(case: Case, game_files: GameFiles, hlvs_check: Any) -> None:
    path = _write(game_files, case)
    required = "--require-images" in case.args
    problems = check_game(path, images_required=required)
    hits = [
        p
        for p in problems
        if p.severity == "error"
        and Path(p.file).name == case.file
        and p.pointer in (case.pointer, "" if case.pointer == "/" else case.pointer)
    ]
    assert hits, "\n".join(str(p) for p in problems)
    problem = hits[0]
    assert case.fragment in f"{problem.message} {problem.expected}", str(problem)
    if case.suggestion:
        assert problem.suggestion == f'"{case.suggestion}"', str(problem)

    with pytest.raises(ConfigError) as raised:
        load_game(path, images_required=required)
    assert problem in raised.value.problems

    run = hlvs_check(path, *case.args)
    assert run.code == 2
    if case.pointer == "/":  # a whole file's problem reads FILE: message, no pointer
        assert f"{case.file}: " in run.out and f"{case.file}: /: " not in run.out, run.out
    else:
        assert f"{case.file}: {case.pointer}: " in run.out
    assert "ok (" not in run.out.splitlines()[-1]


def test_every_problem_is_reported_at_once(game_files: GameFiles) -> None:
    game_files.game["type"] = "FRIENDLY"
    game_files.game["blue"]["ports"][0] = 10001
    game_files.red["players"]["2"][HALF]["translation"][0] = 2.0
    del game_files.blue["name"]
    game_files.blue["players"]["3"][HALF]["translation"][0] = 0.5
    with pytest.raises(ConfigError) as raised:
        load_game(game_files.write())
    where = {(Path(p.file).name, p.pointer) for p in raised.value.problems}
    assert {
        ("game.json", "/type"),
        ("game.json", "/blue/ports/0"),
        ("team_red.json", f"/players/2/{HALF}/translation/0"),
        ("team_blue.json", "/name"),
        ("team_blue.json", f"/players/3/{HALF}/translation/0"),
    } <= where
