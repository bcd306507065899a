"""A real match against a red robot that attacks log collection: 1,500 nested folders, a 3 GB
sparse file with hard links, and a stdout flood. Collection survives, copies the data once, caps
the console output, names the cuts in report.json, and leaves nothing behind. While it plays,
``hlvs cleanup --match`` of look-alike ids ("attack 1a2b", "attack_1a2b") touches nothing of it."""

from __future__ import annotations

import json
import os
import stat
import subprocess
import sys
import time
from pathlib import Path
from types import SimpleNamespace
from typing import Any

import docker
import pytest

from orchestrator.match import logfs
from orchestrator.match.layout import ROBOT_CONSOLE_BYTES
from tests.integration.attack.conftest import (
    REPO,
    RUNTIMES,
    Prepare,
    Prepared,
    left_behind,
    under_runtime,
)

pytestmark = [pytest.mark.docker, pytest.mark.root]

LOG_FOLDER_GB = 0.05
FLOOD_MB = 48


@pytest.fixture(scope="module", **RUNTIMES)
def hoarder(request: pytest.FixtureRequest, prepare: Prepare,
            docker_client: docker.DockerClient) -> tuple[Prepared, Any, list[str]]:
    """The match (robots under the engine's default runtime, then under gVisor's runsc), and
    while it plays ``hlvs cleanup --match`` of ids that differ from its id only in punctuation
    or spaces (the cleanup reports are kept in ``done.cleanups``)."""
    limits = under_runtime(request.param, docker_client, {"log_folder_gb": LOG_FOLDER_GB})
    match = prepare("nest=1500", "sparse=5", f"flood={FLOOD_MB}", half_s=5.0,
                    game={"limits": limits})
    process = match.start()
    mount = logfs.state_dir() / "logfs" / logfs.safe_name(match.match_id) / "red-1"
    deadline = time.monotonic() + 120
    while not (mount / "attacks.json").is_file():
        assert process.poll() is None and time.monotonic() < deadline, process.communicate()
        time.sleep(0.2)
    cleanups = []
    for variant in (match.match_id.replace("-", " "), match.match_id.replace("-", "_")):
        cleaned = subprocess.run(
            [sys.executable, "-m", "hlvs", "cleanup", "--match", variant],
            capture_output=True, text=True, timeout=120, cwd=REPO, check=False,
            env={**os.environ, "PYTHONPATH": str(REPO)})
        assert cleaned.returncode == 0, cleaned.stderr[-2000:]
        cleanups.append(json.loads(cleaned.stdout))
    still_playing = process.poll() is None and str(mount) in Path("/proc/mounts").read_text()
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr[-3000:]
    done = SimpleNamespace(stdout=stdout, stderr=stderr, cleanups=cleanups,
                           still_playing=still_playing)
    return match, done, left_behind(docker_client, match.match_id)


def test_cleanup_of_a_look_alike_match_id_leaves_the_running_match_alone(
    hoarder: tuple[Prepared, Any, list[str]],
) -> None:
    match, done, _ = hoarder
    assert done.still_playing  # the cleanups ran during the match
    for report in done.cleanups:
        assert (report["containers"], report["networks"], report["host_objects"]) == ([], [], 0)
    assert match.report()["status"] == "success"
    assert (match.out / "teams/red/1/robocup-logs/attacks.json").is_file()


def test_the_match_record_is_complete_and_nothing_is_left(
    hoarder: tuple[Prepared, Any, list[str]],
) -> None:
    match, done, leftovers = hoarder
    assert "RecursionError" not in done.stderr
    assert leftovers == []
    results = match.results()
    assert results["final_state"] == "FINISHED" and results["status"] == "success"
    seen = json.loads((match.out / "teams/red/1/robocup-logs/attacks.json").read_text())
    assert seen["nest"] == 1500 and seen["sparse"]["links"] == 5 and seen["flood"] == FLOOD_MB
    assert (match.out / "teams/blue/1/stdout.log").is_file()
    modes = {p: stat.S_IMODE(p.lstat().st_mode) for p in [match.out, *match.out.rglob("*")]}
    assert {m for p, m in modes.items() if p.is_dir()} == {0o700}
    assert {m for p, m in modes.items() if p.is_file()} == {0o600}


def test_deep_folders_are_cut_at_the_depth_limit(hoarder: tuple[Prepared, Any, list[str]]
                                                ) -> None:
    match, _, _ = hoarder
    folder = match.results()["robots"]["red-1"]["log_folder"]
    deep = [s for s in folder["skipped"] if "nested deeper than" in s["kind"]]
    assert len(deep) == 1 and deep[0]["path"].startswith("d/d/d/")


def test_a_sparse_file_and_its_links_cost_the_host_their_data_once(
    hoarder: tuple[Prepared, Any, list[str]],
) -> None:
    match, _, _ = hoarder
    logs = match.out / "teams/red/1/robocup-logs"
    copy = logs / "sparse.bin"
    assert copy.stat().st_size == 3 * 10**9 + 4
    assert copy.stat().st_blocks * 512 < 1 << 20
    assert {(logs / f"link{i}").stat().st_ino for i in range(5)} == {copy.stat().st_ino}
    folder = match.results()["robots"]["red-1"]["log_folder"]
    assert folder["bytes"] < LOG_FOLDER_GB * 1e9
    total = sum(p.lstat().st_blocks * 512 for p in match.out.rglob("*") if p.is_file())
    assert total < 100e6  # the whole output, flood included


def test_a_stdout_flood_is_capped_and_named_in_the_report(
    hoarder: tuple[Prepared, Any, list[str]],
) -> None:
    match, _, _ = hoarder
    stdout = match.out / "teams/red/1/stdout.log"
    assert stdout.stat().st_size <= ROBOT_CONSOLE_BYTES // 2
    report = match.report()
    assert report["status"] == "success"
    assert {"robot": "red-1", "what": "stdout.log",
            "reason": f"cut at the limit of {ROBOT_CONSOLE_BYTES // 2} bytes"} in report["logs_cut"]
    assert not any(cut["robot"].startswith("blue") for cut in report["logs_cut"])
    assert match.results()["robots"]["red-1"]["limits"]["console_bytes"] == ROBOT_CONSOLE_BYTES
