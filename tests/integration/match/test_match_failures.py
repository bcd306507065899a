"""Typed failures and forfeits: every path still writes results.json and report.json and leaves
no container, network, firewall rule or mount behind."""

from __future__ import annotations

import json
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import pytest

from orchestrator.match.logfs import state_dir
from orchestrator.runtime.port import ContainerRequest, NetworkRequest
from tests.integration.match.conftest import MatchFactory

pytestmark = [pytest.mark.docker, pytest.mark.root]


def _nothing_left(runtime: Any, match_id: str) -> None:
    assert runtime.list_project(match_id=match_id) == []
    for tool in ("iptables", "ip6tables"):
        rules = subprocess.run([tool, "-S", "INPUT"], capture_output=True, text=True).stdout
        assert f"hlvs-runner:{match_id}" not in rules
    assert str(state_dir() / "logfs" / match_id) not in Path("/proc/mounts").read_text()


def _report(out: Path) -> dict[str, Any]:
    return dict(json.loads((out / "report.json").read_text()))


def test_team_without_a_usable_image_forfeits(play: MatchFactory, runtime: Any) -> None:
    outcome = play(red=[["env"]], blue=[["env"], ["env"]],
                   blue_image="hlvs-runner-test/does-not-exist:1")
    assert _report(outcome.out_dir) == {"status": "success"}
    results = json.loads((outcome.out_dir / "results.json").read_text())
    assert results["forfeit"]["team"] == "blue"
    assert results["winner"] == "red"
    assert "not found" in results["robots"]["blue-2"]["image_error"]
    _nothing_left(runtime, outcome.match_id)


def test_no_usable_image_at_all_is_an_image_pull_failure(play: MatchFactory) -> None:
    outcome = play(red=[["env"]], blue=[["env"]], red_image=None,
                   blue_image="hlvs-runner-test/does-not-exist:1")
    report = _report(outcome.out_dir)
    assert report["status"] == "failed"
    assert report["failure_class"] == "image_pull"


def test_simulator_crash_fails_the_match_and_logs_are_still_collected(
    play: MatchFactory, runtime: Any
) -> None:
    outcome = play(red=[["env"]], blue=[["env"]], sim=("1", "5"))
    report = _report(outcome.out_dir)
    assert report["failure_class"] == "simulator"
    assert "code 5" in report["cause"]
    assert "fake simulator done" in report["cause"]
    assert (outcome.out_dir / "teams/red/1/stdout.log").read_text().startswith("robot red-1")
    assert (outcome.out_dir / "simulator/stderr.log").is_file()
    assert (outcome.out_dir / "results.json").is_file()
    _nothing_left(runtime, outcome.match_id)


def test_stop_request_stops_everything_cleanly(play: MatchFactory, runtime: Any) -> None:
    stop = threading.Event()
    red_logs: list[Path] = []  # red 1's /robocup-logs on the host, once its container is made

    def note_red_logs(request: ContainerRequest | NetworkRequest) -> None:
        if isinstance(request, ContainerRequest) and request.name.endswith("-red-1"):
            red_logs.append(next(m.source for m in request.mounts
                                 if m.target == "/robocup-logs"))

    def interrupt_when_playing() -> None:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            if red_logs and (red_logs[0] / "ready.txt").exists():
                stop.set()
                return
            time.sleep(0.05)

    thread = threading.Thread(target=interrupt_when_playing, daemon=True)
    thread.start()
    started = time.monotonic()
    outcome = play(red=[["sigterm"]], blue=[["env"]], sim=("60",), on_created=note_red_logs,
                   stop_event=stop)
    assert time.monotonic() - started < 40
    report = _report(outcome.out_dir)
    assert report["failure_class"] == "interrupted"
    term = (outcome.out_dir / "teams/red/1/robocup-logs/term.txt").read_text()
    assert term == "got SIGTERM\nflushed\n"
    _nothing_left(runtime, outcome.match_id)


def test_silent_simulator_telemetry_fails_the_match(play: MatchFactory, runtime: Any) -> None:
    outcome = play(red=[["env"]], blue=[["env"]], sim=("60",), telemetry_silence_s=4.0)
    report = _report(outcome.out_dir)
    assert report["failure_class"] == "simulator"
    assert "telemetry silent" in report["cause"]
    assert (outcome.out_dir / "simulator/stdout.log").read_text().startswith("fake simulator up")
    assert (outcome.out_dir / "teams/blue/1/stdout.log").is_file()
    _nothing_left(runtime, outcome.match_id)
