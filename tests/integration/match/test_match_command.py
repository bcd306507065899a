"""``hlvs match GAME.json`` through the CLI: config loading, image resolution (local images are
pinned by id), the real simulator, results; and a config error exits 2 without a traceback."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main as hlvs
from orchestrator import add_scrimmage_arguments as add_arguments
from orchestrator.errors import OrchestratorError
from orchestrator.match.logfs import state_dir
from orchestrator.match.scrimmage import ScrimmageRequest, write_files

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_match_command_plays_a_game_file(tmp_path: Path, test_image: str, runtime: Any,
                                         capsys: pytest.CaptureFixture[str],
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    """Relative paths as a user types them: the game file and ``--out`` (a bind-mount source)."""
    try:
        from orchestrator.project_images import project_image

        project_image("simulator")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"simulator image unavailable: {exc}")
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = parser.parse_args([
        "--players", "2", "--half-duration", "3", "--ready-duration", "2", "--minimum-play", "0",
        "--wait-before-ready", "1",
        "--match-id", "cmd-test", "--red-image", test_image, "--blue-image", test_image,
        "--robot-command", "python3 /opt/t/robot.py env",
    ])
    write_files(ScrimmageRequest.from_options(args), tmp_path / "config")
    out = tmp_path / "out"
    monkeypatch.chdir(tmp_path)
    try:
        code = hlvs(["match", "config/game.json", "--out", "out", "--grace", "1"])
    finally:
        hlvs(["cleanup", "--match", "cmd-test"])
    printed = capsys.readouterr()
    assert code == 0, printed.err[-3000:]
    assert f"results in {out}" in printed.out
    results = json.loads((out / "results.json").read_text())
    assert results["final_state"] == "FINISHED"
    robot = results["robots"]["blue-2"]
    assert robot["digest"] and robot["image_error"] is None
    env = json.loads((out / "teams/blue/2/robocup-logs/env.json").read_text())["env"]
    assert env["ROBOCUP_ROBOT_ID"] == "2" and env["ROBOCUP_TEAM_COLOR"] == "blue"
    assert results["limits"]["grace_period_s"] == 1.0
    assert runtime.list_project(match_id="cmd-test") == []


def test_match_command_reports_a_bad_game_file(tmp_path: Path,
                                               capsys: pytest.CaptureFixture[str],
                                               monkeypatch: pytest.MonkeyPatch) -> None:
    game = tmp_path / "game.json"
    game.write_text('{"type": "NORMAL"}')
    monkeypatch.chdir(tmp_path)
    assert hlvs(["match", "game.json", "--out", "out"]) == 2
    err = capsys.readouterr().err
    assert str(game) in err and "Traceback" not in err
    assert not (tmp_path / "out").exists()


def test_sigterm_to_hlvs_match_stops_everything_and_exits_130(
    tmp_path: Path, test_image: str, runtime: Any
) -> None:
    import os
    import signal
    import subprocess
    import sys
    import time

    try:
        from orchestrator.project_images import project_image

        project_image("simulator")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"simulator image unavailable: {exc}")
    parser = argparse.ArgumentParser()
    add_arguments(parser)
    args = parser.parse_args([
        "--half-duration", "600", "--wait-before-ready", "60", "--match-id", "sig-test",
        "--red-image", test_image, "--blue-image", test_image,
        "--robot-command", "python3 /opt/t/robot.py sigterm",
    ])
    game = write_files(ScrimmageRequest.from_options(args), tmp_path / "config")
    out = tmp_path / "out"
    repo = Path(__file__).resolve().parents[3]
    process = subprocess.Popen(
        [sys.executable, "-m", "hlvs", "match", str(game), "--out", str(out),
         "--grace", "5"],
        cwd=repo, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
    )
    try:
        ready = state_dir() / "logfs" / "sig-test" / "red-1" / "ready.txt"
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not ready.exists():
            if process.poll() is not None:
                pytest.fail(f"hlvs match ended early: {process.communicate()[1][-2000:]}")
            time.sleep(0.1)
        assert ready.exists(), "the robot did not get ready"
        os.kill(process.pid, signal.SIGTERM)
        _, err = process.communicate(timeout=60)
        assert process.returncode == 130, err[-2000:]
        report = json.loads((out / "report.json").read_text())
        assert report["failure_class"] == "interrupted"
        term = (out / "teams/red/1/robocup-logs/term.txt").read_text()
        assert term == "got SIGTERM\nflushed\n"
        assert runtime.list_project(match_id="sig-test") == []
    finally:
        if process.poll() is None:
            process.kill()
        hlvs(["cleanup", "--match", "sig-test"])
