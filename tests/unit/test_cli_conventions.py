"""Every ``hlvs`` command follows the command-line conventions (see ``hlvs/cli.py``):
help text on every command and option, the right program name, ``--help`` exits 0, building the
parser imports nothing heavy, ``--version``, ``-q``/``-v`` and the documented exit codes."""

from __future__ import annotations

import argparse
import json
import logging
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path
from typing import Any

import pytest

from contracts.match_results import Forfeit
from hlvs.cli import build_parser, log_level, main, walk
from orchestrator.exitcodes import ExitCode

# Modules that make `hlvs --help` slow; a command imports them when it runs, never at parse time.
HEAVY = (
    "docker", "pyroute2", "jsonschema", "yaml", "mujoco", "numpy", "zenoh", "boto3", "botocore",
    "paramiko", "sqlalchemy", "fastapi", "uvicorn", "pydantic", "starlette", "rich", "requests",
    "urllib3", "apscheduler", "httpx", "gymnasium", "google.protobuf", "asyncssh",
    "orchestrator.config", "orchestrator.engine", "orchestrator.match", "orchestrator.delivery",
    "tournament", "simulator", "referee",
)


def _command_paths() -> list[tuple[str, ...]]:
    paths: list[tuple[str, ...]] = []
    for parser in walk(build_parser()):
        words = tuple(parser.prog.split()[1:])
        paths.append(words)
    return sorted(set(paths))


def undocumented(help_text: str) -> list[str]:
    """Items of an argparse help listing (options, arguments, sub-commands) without help text."""
    lines = help_text.splitlines()
    missing = []
    in_listing = False
    for i, line in enumerate(lines):
        if line and not line.startswith(" "):
            in_listing = line.endswith(":") and not line.startswith("usage:")
            continue
        item = re.match(r"^  (\S.*)$", line)
        if not in_listing or not item:
            continue
        if re.search(r"\S {2,}\S", item.group(1)):
            continue  # help on the same line
        following = lines[i + 1] if i + 1 < len(lines) else ""
        if following.startswith("   ") and following.strip():
            continue  # help on the next line, indented deeper
        missing.append(item.group(1).strip())
    return missing


def test_the_help_checker_finds_an_option_without_help() -> None:
    parser = argparse.ArgumentParser(prog="x")
    parser.add_argument("--with-help", help="documented")
    parser.add_argument("--without-help")
    parser.add_argument("positional")
    parser.add_argument(
        "--a-very-long-option-name-that-wraps", metavar="LONG_METAVAR", help="on the next line"
    )
    assert undocumented(parser.format_help()) == ["positional", "--without-help WITHOUT_HELP"]


def test_every_command_has_help_text_in_the_parser_tree() -> None:
    for parser in walk(build_parser()):
        for action in parser._actions:
            if isinstance(action, argparse._SubParsersAction):
                listed = {a.dest for a in action._choices_actions}
                assert set(action.choices) <= listed, f"{parser.prog}: sub-command without help"
            elif action.help is None:
                pytest.fail(f"{parser.prog}: {action.option_strings or action.dest} has no help")


def test_every_command_help_exits_0_with_its_name_and_documents_every_option() -> None:
    paths = _command_paths()
    assert ("check",) in paths and ("bench", "sim") in paths and ("images", "pull") in paths

    def run(words: tuple[str, ...]) -> tuple[tuple[str, ...], subprocess.CompletedProcess[str]]:
        command = [sys.executable, "-m", "hlvs", *words, "--help"]
        return words, subprocess.run(command, capture_output=True, text=True, timeout=120)

    with ThreadPoolExecutor(max_workers=4) as pool:
        results = list(pool.map(run, paths))
    failures = []
    for words, done in results:
        name = " ".join(("hlvs", *words))
        if done.returncode != 0:
            failures.append(f"{name} --help exited {done.returncode}: {done.stderr[-300:]}")
            continue
        if not re.match(rf"usage: {re.escape(name)}( |$)", done.stdout):
            failures.append(f"{name} --help: usage line {done.stdout.splitlines()[:1]}")
        for item in undocumented(done.stdout):
            failures.append(f"{name}: {item!r} has no help text")
    assert not failures, "\n".join(failures)


def test_building_the_parser_imports_nothing_heavy() -> None:
    code = (
        "import json, sys\n"
        "from hlvs.cli import build_parser\n"
        "build_parser()\n"
        "print(json.dumps(sorted(sys.modules)))\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    loaded = json.loads(done.stdout)
    heavy = sorted(
        m for m in loaded if any(m == h or m.startswith(h + ".") for h in HEAVY)
    )
    assert not heavy, f"imported while building the parser: {heavy[:20]}"


def test_version(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert re.fullmatch(r"hlvs \d+\.\d+\S*\n", capsys.readouterr().out)


def test_verbosity_moves_the_command_default_by_one_step_per_flag() -> None:
    parser = build_parser()
    assert log_level(parser.parse_args(["check", "x.json"])) == logging.WARNING
    assert log_level(parser.parse_args(["-v", "check", "x.json"])) == logging.INFO
    assert log_level(parser.parse_args(["check", "-vv", "x.json"])) == logging.DEBUG
    assert log_level(parser.parse_args(["check", "-q", "x.json"])) == logging.ERROR
    assert log_level(parser.parse_args(["match", "game.json"])) == logging.INFO
    assert log_level(parser.parse_args(["match", "-q", "game.json"])) == logging.WARNING


def test_unknown_argument_is_an_input_error(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_info:
        main(["check", "--no-such-option", "x.json"])
    assert exit_info.value.code == ExitCode.INVALID
    assert "unrecognized arguments: --no-such-option" in capsys.readouterr().err


def test_a_missing_state_file_is_invalid_input_like_every_missing_file(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    missing = tmp_path / "missing.sqlite"
    assert main(["schedule", "status", "--state", str(missing)]) == ExitCode.INVALID
    assert f"{missing}: no such state file" in capsys.readouterr().err
    assert main(["check", str(tmp_path / "missing.json")]) == ExitCode.INVALID


def test_check_json_and_github_formats(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    bad = tmp_path / "team_config.json"
    bad.write_text(json.dumps({"name": "x", "players": {"1": {"dockerTag": 5}}}, indent=2))
    tag_line = bad.read_text().splitlines().index('      "dockerTag": 5') + 1
    assert main(["check", "--json", str(bad)]) == ExitCode.INVALID
    report = json.loads(capsys.readouterr().out)
    assert report["valid"] is False
    (entry,) = report["files"]
    assert entry["file"] == str(bad) and entry["valid"] is False
    pointers = {p["pointer"] for p in entry["problems"]}
    assert any(p.startswith("/players/1") for p in pointers), pointers

    assert main(["check", "--format", "github", str(bad)]) == ExitCode.INVALID
    lines = capsys.readouterr().out.splitlines()
    assert lines and all(line.startswith("::error file=") for line in lines), lines
    assert any("title=/players/1" in line for line in lines), lines
    assert any(f"line={tag_line},title=/players/1/dockerTag" in line for line in lines), lines
    assert all("\n" not in line.split("::", 2)[2] for line in lines)


def test_compose_json_names_the_files_and_both_compose_commands(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    game = Path(__file__).parents[2] / "configs" / "examples" / "scrimmage_1v1" / "game.json"
    output = tmp_path / "match" / "docker-compose.yml"
    code = main(["compose", str(game), "-o", str(output), "--simulator-image", "sim:x", "--json"])
    assert code == ExitCode.OK
    printed = json.loads(capsys.readouterr().out)
    assert printed["compose_file"] == str(output) and Path(printed["match_spec"]).is_file()
    assert printed["command"].startswith("docker compose -f docker-compose.yml up")
    assert printed["command_v1"].startswith("docker-compose -f docker-compose.yml up")
    assert "version:" not in output.read_text()


def test_an_output_folder_that_cannot_be_made_is_one_line_naming_it(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    game = Path(__file__).parents[2] / "configs" / "examples" / "scrimmage_1v1" / "game.json"
    in_the_way = tmp_path / "notes.txt"
    in_the_way.write_text("kept\n")
    output = in_the_way / "docker-compose.yml"
    code = main(["compose", str(game), "-o", str(output), "--simulator-image", "sim:x"])
    assert code == ExitCode.INVALID
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert [line for line in err.splitlines() if line] == [
        f"hlvs: {in_the_way}: a file where a folder is needed"]
    assert in_the_way.read_text() == "kept\n"


def test_a_full_disk_is_the_host_s_trouble(monkeypatch: pytest.MonkeyPatch,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    import errno

    from hlvs.commands import check

    def full(args: argparse.Namespace) -> int:
        raise OSError(errno.ENOSPC, "No space left on device", "/srv/matches/m1/replay.hlvsrec")

    monkeypatch.setattr(check, "run", full)  # the parser is built at each call of main
    code = main(["check", "x.json"])
    assert code == ExitCode.INFRASTRUCTURE, capsys.readouterr().err
    assert capsys.readouterr().err.strip() == (
        "hlvs: /srv/matches/m1/replay.hlvsrec: No space left on device")


@pytest.mark.parametrize(
    ("results", "failure", "code"),
    [
        ({"score": {"red": 1, "blue": 0}, "winner": "red"}, None, ExitCode.OK),
        ({"forfeit": Forfeit(team="blue", winner="red", reason="no usable image",
                             score={"red": 0, "blue": 0})}, None, ExitCode.FORFEIT),
        ({}, ("team_crash", "red-1 crashed"), ExitCode.FAILED),
        ({}, ("infrastructure", "engine gone"), ExitCode.INFRASTRUCTURE),
        ({}, ("interrupted", "SIGTERM"), ExitCode.INTERRUPTED),
    ],
)
def test_match_exit_codes_and_json(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], results: dict[str, Any],
    failure: tuple[str, str] | None, code: ExitCode,
) -> None:
    from contracts.match_results import MatchLimits, MatchResults
    from hlvs.commands.outcome import summarize
    from orchestrator.match import Failure, FailureClass, MatchOutcome

    failed = Failure(failure_class=FailureClass(failure[0]), cause=failure[1]) if failure \
        else None
    limits = MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                         team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                         allow_internet=False, host_controls=None)
    outcome = MatchOutcome(
        match_id="m1", out_dir=tmp_path, bringup_s=None, failure=failed,
        results=MatchResults(match_id="m1", seed=1, status="failed" if failed else "success",
                             failure=failed, limits=limits, **results),
    )
    assert summarize(outcome) == code
    capsys.readouterr()
    assert summarize(outcome, as_json=True) == code
    printed = json.loads(capsys.readouterr().out)
    assert printed["exit_code"] == code and printed["match_id"] == "m1"
    assert printed["out_dir"] == str(tmp_path)
    if failure:
        assert printed["failure"] == {"class": failure[0], "cause": failure[1]}


def test_check_prints_a_credentials_warning_once(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    credentials = tmp_path / "credentials.json"
    credentials.write_text(json.dumps({"type": "sftp", "credentials": {
        "hostname": "logs.example", "username": "u", "password": "p", "path": "/upload"}}))
    credentials.chmod(0o644)
    assert main(["check", str(credentials)]) == ExitCode.OK
    printed = capsys.readouterr()
    assert printed.out.count("readable by group or others") == 1, printed.out
    assert "readable by group or others" not in printed.err
