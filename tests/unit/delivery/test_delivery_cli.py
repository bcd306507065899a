"""`hlvs logs enqueue|status|deliver` without servers (a game.json from the examples)."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from hlvs.cli import main

EXAMPLES = Path(__file__).resolve().parents[3] / "configs" / "examples"


def game_with_credentials(tmp_path: Path) -> Path:
    for name in ("game.json", "team_red.json", "team_blue.json"):
        shutil.copy(EXAMPLES / "adult_3v3" / name, tmp_path / name)
    shutil.copy(EXAMPLES / "credentials" / "s3.json", tmp_path / "red_credentials.json")
    (tmp_path / "red_credentials.json").chmod(0o600)
    game = json.loads((tmp_path / "game.json").read_text())
    game["red"]["credentials"] = "red_credentials.json"
    (tmp_path / "game.json").write_text(json.dumps(game))
    return tmp_path / "game.json"


def test_enqueue_from_game_json_then_status(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    game = game_with_credentials(tmp_path)
    match = tmp_path / "out"
    for color in ("red", "blue"):
        (match / "teams" / color / f"{color}-1").mkdir(parents=True)
        (match / "teams" / color / f"{color}-1" / "stdout.log").write_text("hello\n")
    store = tmp_path / "store"
    args = ["logs", "enqueue", str(match), "--game", str(game), "--match-id", "final-1"]
    assert main([*args, "--store", str(store)]) == 0
    assert "queued final-1 Tall Team: 1 files" in capsys.readouterr().out
    assert main(["logs", "status", "--store", str(store), "--json"]) == 0
    sets = json.loads(capsys.readouterr().out)
    assert {(s["team"], s["credentials"] is not None) for s in sets} == {
        ("Tall Team", True),
        ("Big Feet", False),
    }

    (match / "teams" / "red" / "red-1").mkdir(parents=True)
    (match / "teams" / "red" / "red-1" / "stdout.log").write_text("again\n")
    assert main([*args[:-1], "final-2", "--store", str(store), "--json"]) == 0
    queued = json.loads(capsys.readouterr().out)
    assert {(s["match_id"], s["team"]) for s in queued} >= {("final-2", "Tall Team")}


def test_enqueue_rejects_a_missing_match_folder(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    game = game_with_credentials(tmp_path)
    code = main(
        [
            "logs",
            "enqueue",
            str(tmp_path / "nope"),
            "--game",
            str(game),
            "--store",
            str(tmp_path / "store"),
        ]
    )
    assert code == 2 and "no such match folder" in capsys.readouterr().err


def test_deliver_without_credentials_fails_with_the_cause(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    game = game_with_credentials(tmp_path)
    match = tmp_path / "out"
    (match / "teams" / "blue").mkdir(parents=True)
    (match / "teams" / "blue" / "x.log").write_text("x")
    monkeypatch.setenv("HLVS_LOG_STORE", str(tmp_path / "store"))
    assert main(["logs", "enqueue", str(match), "--game", str(game)]) == 0
    capsys.readouterr()
    assert main(["logs", "deliver", "--team", "Big Feet", "--json"]) == 1
    [line] = capsys.readouterr().out.splitlines()
    outcome = json.loads(line)
    assert outcome["team"] == "Big Feet" and outcome["error_kind"] == "config"
    assert main(["logs", "status"]) == 0
    assert "last error (config)" in capsys.readouterr().out


def test_a_store_that_is_not_there_is_said_and_not_made(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    """Run from another folder than the matches' (the default store is ./log-store), or with a
    mistyped --store: "nothing waiting" says where it looked, and no empty store is left."""
    monkeypatch.chdir(tmp_path)
    monkeypatch.delenv("HLVS_LOG_STORE", raising=False)
    assert main(["logs", "status"]) == 0
    assert capsys.readouterr().out.strip() == (
        f"no log sets are waiting: there is no log store at {tmp_path / 'log-store'} "
        "(--store DIR or $HLVS_LOG_STORE names the one the matches queued to)")
    typo = tmp_path / "log-stroe"
    assert main(["logs", "deliver", "--store", str(typo)]) == 0
    assert f"nothing to deliver: there is no log store at {typo}" in capsys.readouterr().out
    assert main(["logs", "deliver", "--store", str(typo), "--json"]) == 0
    assert capsys.readouterr().out == ""
    assert not typo.exists() and not (tmp_path / "log-store").exists()
    typo.mkdir()  # an empty store: nothing to add
    assert main(["logs", "status", "--store", str(typo)]) == 0
    assert capsys.readouterr().out.strip() == "no log sets are waiting"
