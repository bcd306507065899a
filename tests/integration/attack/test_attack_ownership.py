"""Commands that come at the wrong moment: a second start of a running match id, ``hlvs
cleanup`` during a match, and the orchestrator killed mid-game (then ``hlvs cleanup``)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import docker
import pytest

from orchestrator.engine import LABEL_MATCH, LABEL_ROLE
from orchestrator.match import logfs
from tests.integration.attack.conftest import REPO, Prepare, Prepared, left_behind

pytestmark = [pytest.mark.docker, pytest.mark.root]


def _hlvs(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "hlvs", *args], capture_output=True,
                          text=True, timeout=180, cwd=REPO, check=False,
                          env={**os.environ, "PYTHONPATH": str(REPO)})


def _wait_for_attacks(match: Prepared, process: subprocess.Popen[str]) -> None:
    """Until red 1 has written its attacks.json (the match is under way)."""
    mount = logfs.state_dir() / "logfs" / logfs.safe_name(match.match_id) / "red-1"
    deadline = time.monotonic() + 90
    while time.monotonic() < deadline:
        if (mount / "attacks.json").is_file():
            return
        assert process.poll() is None, process.communicate()
        time.sleep(0.2)
    raise AssertionError("the match did not get under way")


def _running(client: docker.DockerClient, match_id: str) -> list[str]:
    return sorted(c.name for c in client.containers.list(
        filters={"label": [f"{LABEL_MATCH}={match_id}", f"{LABEL_ROLE}=robot"]}))


def _wait_running(client: docker.DockerClient, match_id: str, count: int) -> list[str]:
    """The robots start side by side: red 1 may have written its attacks before blue 1 runs."""
    deadline = time.monotonic() + 60
    while len(robots := _running(client, match_id)) < count:
        if time.monotonic() > deadline:
            break
        time.sleep(0.2)
    return robots


def test_second_start_and_cleanup_leave_a_running_match_alone(
    prepare: Prepare, docker_client: docker.DockerClient,
) -> None:
    match = prepare("special-files", half_s=10.0)
    first = match.start()
    try:
        _wait_for_attacks(match, first)
        robots = _wait_running(docker_client, match.match_id, 2)
        assert len(robots) == 2
        second = subprocess.run(match.command(), capture_output=True, text=True, timeout=120,
                                cwd=REPO, check=False,
                                env={**os.environ, "PYTHONPATH": str(REPO)})
        assert second.returncode == 1, second.stderr[-2000:]
        assert f"match {match.match_id} is already running" in second.stderr
        assert f"pid {first.pid}" in second.stderr and str(match.out) in second.stderr
        cleaned = _hlvs("cleanup")
        assert cleaned.returncode in (0, 1), cleaned.stderr[-2000:]
        report = json.loads(cleaned.stdout.strip().splitlines()[-1])
        assert not any(match.match_id in name for name in report["containers"])
        assert any(s.startswith(f"{match.match_id}: its orchestrator") for s in report["skipped"])
        assert _running(docker_client, match.match_id) == robots
        named = _hlvs("cleanup", "--match", match.match_id)
        assert named.returncode == 1 and "already running" in named.stderr
        stdout, stderr = first.communicate(timeout=180)
    finally:
        if first.poll() is None:
            first.kill()
    assert first.returncode == 0, stderr[-3000:]
    assert match.report() == {"status": "success"}
    assert match.results()["final_state"] == "FINISHED"
    assert (match.out / "teams/red/1/robocup-logs/sub/kept.txt").is_file()
    assert "attacks done" in (match.out / "teams/red/1/stdout.log").read_text()
    assert left_behind(docker_client, match.match_id) == []


def test_orchestrator_killed_then_cleanup_salvages_the_teams_logs(
    prepare: Prepare, docker_client: docker.DockerClient,
) -> None:
    match = prepare("special-files", half_s=60.0)
    process = match.start()
    try:
        _wait_for_attacks(match, process)
        time.sleep(1.0)
        os.kill(process.pid, signal.SIGKILL)
        process.communicate(timeout=30)
    finally:
        if process.poll() is None:
            process.kill()
    assert _running(docker_client, match.match_id)  # the match plays on without its owner
    cleaned = _hlvs("cleanup")
    assert cleaned.returncode == 0, cleaned.stderr[-3000:]
    report = json.loads(cleaned.stdout.strip().splitlines()[-1])
    assert str(match.out.resolve()) in report["salvaged"]
    assert match.report()["status"] == "failed"
    assert match.report()["failure_class"] == "interrupted"
    for color in ("red", "blue"):
        assert (match.out / "teams" / color / "1" / "stdout.log").is_file()
    assert "attacks done" in (match.out / "teams/red/1/stdout.log").read_text()
    logs = match.out / "teams/red/1/robocup-logs"
    assert json.loads((logs / "attacks.json").read_text())["special_files"]
    assert (logs / "sub" / "kept.txt").read_text() == "kept\n"
    assert not any(p.is_symlink() for p in logs.rglob("*"))
    assert (match.out / "public" / "referee.log").is_file()
    assert left_behind(docker_client, match.match_id) == []
