"""Fault: the Docker engine stopped and started again mid-match (as a service manager restarts
it: SIGTERM, the engine stops every container, exits, and is started again).

On an engine of the test's own (:mod:`tests.integration.faults.own_engine`: the shared engine
is never restarted, it runs other tests' matches), loaded with the project's simulator and stub
images, a real ``hlvs scrimmage`` with ``DOCKER_HOST`` pointing at it.

Outcome: the match fails as ``infrastructure`` with a cause naming the engine (before, the
runner blamed the simulator, "simulator exited with code 137", and with the engine away every
step of collection failed at once: the consoles were lost and the match's containers and
networks left on the engine); the runner waits for the engine to answer again, collects the
consoles the engine still holds and removes everything of the match: nothing is left on the
engine, in the host's firewall or in the mounts, and the teams' logs written until the restart
are kept. The loss is the rest of the match."""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import subprocess
import sys
import time
import uuid
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import docker
import pytest

from tests.integration.faults.own_engine import EngineDidNotStart, OwnEngine

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="a second engine needs root"),
              pytest.mark.skipif(shutil.which("dockerd") is None, reason="no dockerd here")]

REPO = Path(__file__).parents[3]
LABEL_MATCH = "org.hlvs-runner.match"


def _project_images() -> list[str]:
    """The simulator and stub images as ``hlvs scrimmage`` names them, with the images they are
    built on (what it checks for before it plays), built on the shared engine when missing."""
    from orchestrator.project_images import _recipe, ensure_image

    found: list[str] = []
    for name in ("simulator", "stub"):
        while name:
            recipe = _recipe(name)
            found.append(ensure_image(name).reference)
            if recipe.parent is None:
                found.append(recipe.base.reference)
            name = recipe.parent or ""
    return found


@pytest.fixture
def engine(docker_client: docker.DockerClient) -> Iterator[OwnEngine]:
    had_docker0 = Path("/sys/class/net/docker0").exists()
    own = OwnEngine()
    try:
        try:
            own.start()
        except EngineDidNotStart as exc:
            pytest.skip(f"a second Docker engine cannot start here: {exc}")
        own.load(docker_client, _project_images())
        yield own
    finally:
        own.close()
    # the shared engine keeps its default bridge (an engine started with --bridge=none deletes
    # it, and every later container on the default network failed to start)
    assert Path("/sys/class/net/docker0").exists() or not had_docker0


def _match_objects(engine: OwnEngine, match_id: str) -> list[str]:
    with contextlib.closing(engine.client()) as client:
        labelled = {"label": f"{LABEL_MATCH}={match_id}"}
        return ([c.name for c in client.containers.list(all=True, filters=labelled)]
                + [n.name for n in client.networks.list(filters=labelled)])


def _host_leftovers(match_id: str) -> tuple[bool, bool]:
    from orchestrator.match.logfs import state_dir

    rules = subprocess.run(["iptables", "-S", "INPUT"], capture_output=True, text=True).stdout
    return (f"hlvs-runner:{match_id}" in rules,
            str(state_dir() / "logfs" / match_id) in Path("/proc/mounts").read_text())


def _running(engine: OwnEngine, match_id: str) -> dict[str, Any]:
    with contextlib.closing(engine.client()) as client:
        return {c.name: c.attrs["State"] for c in client.containers.list(
            filters={"label": f"{LABEL_MATCH}={match_id}", "status": "running"})}


def test_engine_restarted_mid_match(engine: OwnEngine, tmp_path: Path) -> None:
    from orchestrator.match import start_gate
    from orchestrator.match.layout import short_token
    from orchestrator.match.logfs import safe_name

    match_id = f"eng-{uuid.uuid4().hex[:8]}"
    prefix = f"hlvs-{safe_name(match_id)}"
    engine.open_bridges(f"hl{short_token(match_id, prefix)}{role}" for role in "rbc")
    out = tmp_path / "out"
    env = {**os.environ, "DOCKER_HOST": engine.url, "PYTHONPATH": str(REPO)}
    command = [sys.executable, "-m", "hlvs", "scrimmage", "--players", "1", "--out", str(out),
               "--half-duration", "30", "--minimum-play", "0", "--match-id", match_id,
               "--gpu", "off", "--grace", "1"]
    with (tmp_path / "scrimmage.log").open("w") as printed:
        process = subprocess.Popen(command, cwd=REPO, env=env, stdout=printed,
                                   stderr=subprocess.STDOUT)
    try:
        deadline = time.monotonic() + 240
        # the simulator and 2 robots (behind their start gates; with holders, 2 more)
        expected = 3 if start_gate() is not None else 5
        while len(_running(engine, match_id)) < expected:
            assert process.poll() is None, (tmp_path / "scrimmage.log").read_text()[-3000:]
            assert time.monotonic() < deadline, "the match did not start on the engine"
            time.sleep(1)
        time.sleep(10)  # the robots connect and the game goes on
        assert len(_running(engine, match_id)) == expected, "the match ended before the restart"
        engine.stop()
        engine.start()
        code = process.wait(timeout=300)
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    printed_text = (tmp_path / "scrimmage.log").read_text()
    report = json.loads((out / "report.json").read_text())
    results = json.loads((out / "results.json").read_text())
    cause = report.get("cause", "")
    assert code == 3, printed_text[-3000:]  # infrastructure
    assert report["failure_class"] == "infrastructure", report
    assert f"the Docker engine at {engine.url}" in cause, cause
    assert f"the Docker engine at {engine.url}" in printed_text
    assert "playing" in results["timings_s"], results["timings_s"]  # it was mid-match
    # the consoles, collected once the engine answered again; the teams' own logs folder
    for robot in ("red/1", "blue/1"):
        assert (out / "teams" / robot / "stdout.log").is_file(), robot
        assert (out / "teams" / robot / "robocup-logs").is_dir(), robot
    assert (out / "simulator" / "stderr.log").is_file()
    # nothing left: on the engine, in the host's firewall, in the mounts
    assert _match_objects(engine, match_id) == []
    assert _host_leftovers(match_id) == (False, False)
    cleanup = subprocess.run([sys.executable, "-m", "hlvs", "cleanup", "--match", match_id],
                             cwd=REPO, env=env, capture_output=True, text=True, timeout=120)
    assert cleanup.returncode == 0, cleanup.stderr[-2000:]
    assert _match_objects(engine, match_id) == []
