"""What the command line tells a person who made a mistake or hit a dead service: the exit code
of its kind (README "Exit codes") and one sentence naming what was expected, never a traceback."""

from __future__ import annotations

import json
import socket
from pathlib import Path

import pytest

from hlvs.cli import build_parser, main
from orchestrator import ImagePullError, Problem
from orchestrator.exitcodes import ExitCode

TEAM = Path(__file__).parents[2] / "configs" / "examples" / "scrimmage_1v1" / "team_red.json"


def _closed_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
    return port


def test_pull_exit_codes_tell_the_registry_s_failure_from_the_team_s() -> None:
    from hlvs.commands.images import pull_exit_code

    unreachable = ImagePullError(image="r/x:1", reason="registry r unreachable", transient=True)
    unknown_tag = ImagePullError(image="r/x:1", reason="tag 1 not found in r/x")
    assert pull_exit_code([None, None]) == ExitCode.OK
    assert pull_exit_code([unreachable, None, unreachable]) == ExitCode.INFRASTRUCTURE
    assert pull_exit_code([unreachable, unknown_tag]) == ExitCode.FAILED
    assert pull_exit_code([unknown_tag]) == ExitCode.FAILED


def test_images_pull_from_an_unreachable_registry_exits_3(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    import orchestrator.engine

    team = json.loads(TEAM.read_text())
    team["image"] = f"127.0.0.1:{_closed_port()}/team/robot"
    path = tmp_path / "team.json"
    path.write_text(json.dumps(team))
    monkeypatch.setattr(orchestrator.engine, "connect", lambda: object())  # never pulled
    code = main(["-q", "images", "pull", str(path)])
    out = capsys.readouterr().out
    assert code == ExitCode.INFRASTRUCTURE, out
    assert "unreachable" in out


@pytest.mark.parametrize("given", ["127.0.0.1:8000", "localhost", "ftp://host", "http://"])
def test_a_server_without_http_is_an_input_mistake(
        given: str, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setenv("HLVS_TOKEN", "hlvs_000000000000_" + "x" * 43)
    assert main(["status", "--server", given]) == ExitCode.INVALID
    err = capsys.readouterr().err
    assert f"--server: {given!r} is not the service's URL" in err
    assert "expected http:// or https://" in err and "no answer" not in err
    monkeypatch.setenv("HLVS_SERVER", given)
    assert main(["status"]) == ExitCode.INVALID
    assert "$HLVS_SERVER" in capsys.readouterr().err


def test_token_file_help_says_hlvs_token_is_a_variable() -> None:
    parser = build_parser()
    status = parser._subparsers._group_actions[0].choices["status"]  # type: ignore[union-attr]
    text = " ".join(status.format_help().split())
    assert "the value of the variable HLVS_TOKEN" in text
    assert "default: $HLVS_TOKEN" not in text


@pytest.mark.parametrize(("typed", "meant"), [
    (["chek"], "check"), (["sched"], "schedule"), (["logs", "fecth"], "fetch"),
    (["schedule", "stauts"], "status"),
])
def test_a_mistyped_command_gets_did_you_mean(
        typed: list[str], meant: str, capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exited:
        main(typed)
    assert exited.value.code == ExitCode.INVALID
    assert f"did you mean {meant!r}?" in capsys.readouterr().err


def test_the_command_list_names_logs_fetch(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit):
        main(["--help"])
    assert "(logs fetch)" in " ".join(capsys.readouterr().out.split())


def test_a_problem_of_a_whole_file_names_the_file_without_a_bare_pointer(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert str(Problem("/x/game.json", "", "file not found")) == "/x/game.json: file not found"
    assert str(Problem("/x/g.json", "/red", "bad")) == "/x/g.json: /red: bad"
    missing = tmp_path / "missing.json"
    assert main(["check", str(missing)]) == ExitCode.INVALID
    assert capsys.readouterr().out.splitlines() == [f"{missing}: file not found"]


@pytest.fixture
def elsewhere(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    for name in ("HLVS_SERVICE_DATA_DIR", "HLVS_SERVICE_DATABASE_URL"):
        monkeypatch.delenv(name, raising=False)
    folder = tmp_path / "elsewhere"
    folder.mkdir()
    monkeypatch.chdir(folder)
    return folder


@pytest.mark.parametrize("argv", [["admin", "token", "list"], ["admin", "team", "add", "Ants"],
                                  ["admin", "token", "issue", "--operator"]])
def test_admin_refuses_to_make_a_database_it_was_not_told_of(
        argv: list[str], elsewhere: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(argv) == ExitCode.INVALID
    err = capsys.readouterr().err
    assert f"no service database at {elsewhere / 'service-data' / 'service.sqlite'}" in err
    assert "--data-dir" in err and "Traceback" not in err
    assert not (elsewhere / "service-data").exists()


def test_admin_told_where_makes_the_database_then_finds_it_in_its_folder(
        elsewhere: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["admin", "team", "add", "Ants", "--data-dir", "service-data"]) == 0
    assert main(["admin", "team", "list"]) == 0  # ./service-data has a database now
    assert json.loads(capsys.readouterr().out.splitlines()[-1])["team"] == "Ants"
    monkeypatch.chdir(elsewhere.parent)
    monkeypatch.setenv("HLVS_SERVICE_DATA_DIR", str(elsewhere / "service-data"))
    assert main(["admin", "team", "list"]) == 0
