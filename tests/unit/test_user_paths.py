"""Every path a user gives on the command line is made absolute where it enters (the argument
parser), and messages name the resolved file. ``hlvs render`` forwards its arguments to the
simulator's parser, which does the same (tests/unit/world/test_render_command.py)."""

from __future__ import annotations

from pathlib import Path

import pytest

from hlvs.cli import build_parser
from hlvs.cli import main as hlvs
from orchestrator.paths import user_path

COMMAND_LINES = {
    "check": (["check", "a/game.json", "b.json"], ["files"]),
    "match": (["match", "game.json", "--out", "out"], ["game", "out"]),
    "scrimmage": (["scrimmage", "--out", "here"], ["out"]),
    "scrimmage default": (["scrimmage"], ["out"]),
    "compose": (["compose", "game.json", "-o", "c.yml"], ["game", "output"]),
    "compose default": (["compose", "game.json"], ["output"]),
    "images pull": (["images", "pull", "team.json"], ["team_config"]),
    "logs enqueue": (["logs", "enqueue", "m", "--game", "g.json", "--store", "s"],
                     ["match_dir", "game", "store"]),
    "logs deliver": (["logs", "deliver", "--store", "s"], ["store"]),
    "logs status": (["logs", "status", "--store", "s"], ["store"]),
    "schedule run": (["schedule", "run", "t.yaml", "--state", "s.sqlite"], ["schedule", "state"]),
    "schedule list": (["schedule", "list", "t.yaml", "--state", "s.sqlite"],
                      ["schedule", "state"]),
    "schedule status": (["schedule", "status", "--state", "s.sqlite"], ["state"]),
    "schedule cancel": (["schedule", "cancel", "m1", "--state", "s.sqlite"], ["state"]),
    "schedule standings": (["schedule", "standings", "--state", "s.sqlite"], ["state"]),
    "schedule abort": (["schedule", "abort", "m1", "--state", "s.sqlite", "--reason", "r"],
                       ["state"]),
    "schedule reschedule": (["schedule", "reschedule", "m1", "--state", "s.sqlite"], ["state"]),
    "schedule apply": (["schedule", "apply", "--state", "s.sqlite"], ["state"]),
    "submit": (["submit", "--team-config", "t.json", "--credentials", "c.json",
                "--token-file", "tok"], ["team_config", "credentials", "token_file"]),
    "results": (["results", "sub_1", "-o", "runs"], ["out"]),
    "logs fetch": (["logs", "fetch", "sub_1", "-o", "runs/logs"], ["out"]),
    "serve": (["serve", "--data-dir", "data"], ["data_dir"]),
    "view": (["view", "matches/scrimmage", "r.hlvsrec"], ["paths"]),
    "export": (["export", "r.hlvsrec", "-o", "m.mcap", "--stats", "s.jsonl"],
               ["replay", "output", "stats"]),
}


@pytest.mark.parametrize("name", sorted(COMMAND_LINES))
def test_paths_are_absolute_after_parsing(name: str, tmp_path: Path,
                                          monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    argv, fields = COMMAND_LINES[name]
    args = build_parser().parse_args(argv)
    for field in fields:
        value = getattr(args, field)
        for path in value if isinstance(value, list) else [value]:
            assert isinstance(path, Path) and path.is_absolute(), (field, path)
            assert path.is_relative_to(tmp_path), (field, path)


def test_user_path_folds_dots_and_expands_home(tmp_path: Path,
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert user_path("a/../b/c.json") == tmp_path / "b" / "c.json"
    assert user_path("~/x") == tmp_path / "home" / "x"
    assert user_path("/abs/p") == Path("/abs/p")


def test_check_names_the_resolved_file(tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                       capsys: pytest.CaptureFixture[str]) -> None:
    (tmp_path / "configs").mkdir()
    monkeypatch.chdir(tmp_path / "configs")
    assert hlvs(["check", "../missing/game.json"]) == 2
    out = capsys.readouterr()
    assert str(tmp_path / "missing" / "game.json") in out.out + out.err


def test_schedule_status_names_the_resolved_state_file(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    assert hlvs(["schedule", "status", "--state", "state.sqlite"]) != 0
    err = capsys.readouterr().err
    assert str(tmp_path / "state.sqlite") in err and "no such state file" in err


def test_watch_hint_names_the_replay_as_seen_from_the_cwd(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    from hlvs.commands.outcome import watch_hint

    out = tmp_path / "matches" / "scrimmage"
    assert watch_hint(out) == []  # nothing to watch without a replay
    (out / "public").mkdir(parents=True)
    (out / "public" / "replay.hlvsrec").write_bytes(b"x")
    monkeypatch.chdir(tmp_path)
    hint = "\n".join(watch_hint(out))
    assert "hlvs view matches/scrimmage" in hint
    assert "hlvs render matches/scrimmage/public/replay.hlvsrec -o match.mp4" in hint
    monkeypatch.chdir(tmp_path / "matches" / "scrimmage" / "public")
    assert f"hlvs view {out}" in "\n".join(watch_hint(out))
