"""Fault: ``hlvs serve`` killed (SIGKILL: no shutdown code runs) during a pre-flight check and
during a match, then started again on the same data.

Outcomes:

- killed during a pre-flight: the submission is not recorded (its client's request ends
  without an answer: it submits again, the one thing lost); the check's simulator and robot
  containers, networks and temporary folder are removed by the next start of the service
  (:func:`service.preflight.reclaim_leftovers`), nothing of the check is left;
- killed during a match: the match plays on (its ``hlvs match`` process is in a session of its
  own), the restarted service adopts it (one attempt, the same match id) and records it done
  with its results; nothing is lost.

Real parts: the service as its own process over SQLite, the local Docker pool, the real
pre-flight check and a real match of the project's stub robots."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import httpx
import pytest

from service import Settings
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.tokens import issue
from tests.integration.service.harness import free_port
from tests.unit.service.conftest import wait_for_status

pytestmark = [pytest.mark.docker, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="matches need root (host controls)")]

REPO = Path(__file__).parents[3]
EXAMPLE_TEAM = REPO / "configs" / "examples" / "scrimmage_1v1" / "team_red.json"
LABEL_MATCH = "org.hlvs-runner.match"


def _team_doc(command: str) -> dict[str, Any]:
    doc: dict[str, Any] = json.loads(EXAMPLE_TEAM.read_text())
    doc["name"] = "Alpha"
    doc["players"]["1"]["dockerCmd"] = command
    return doc


class Service:
    """``hlvs serve`` as a process of its own on ``data``."""

    def __init__(self, data: Path, log: Path) -> None:
        self.data = data
        self.port = free_port()
        self.url = f"http://127.0.0.1:{self.port}"
        self.log = log
        self.process: subprocess.Popen[bytes] | None = None

    def env(self) -> dict[str, str]:
        return {**os.environ, "PYTHONPATH": str(REPO), "HLVS_SERVICE_DATA_DIR": str(self.data),
                "HLVS_SERVICE_WORKER_POLL_S": "0.3", "HLVS_SERVICE_TEST_HALF_DURATION_S": "10",
                "HLVS_SERVICE_TEST_READY_DURATION_S": "1", "HLVS_SERVICE_TEST_GRACE_S": "2",
                "HLVS_SERVICE_VIDEO": "0", "HLVS_SERVICE_TEAM_PROJECT_IMAGES": "1",
                "HLVS_SERVICE_PREFLIGHT_TIMEOUT_S": "60", "HLVS_SERVICE_TOKEN_CACHE_S": "0"}

    def start(self) -> None:
        with self.log.open("ab") as out:
            self.process = subprocess.Popen(
                [sys.executable, "-m", "hlvs", "serve", "--port", str(self.port)], cwd=REPO,
                env=self.env(), stdout=out, stderr=subprocess.STDOUT, start_new_session=True)
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            assert self.process.poll() is None, self.log.read_text()[-3000:]
            try:
                if httpx.get(f"{self.url}/v1/health", timeout=2).status_code == 200:
                    return
            except httpx.HTTPError:
                pass
            time.sleep(0.2)
        raise AssertionError(f"the service did not answer: {self.log.read_text()[-3000:]}")

    def kill(self) -> None:
        assert self.process is not None
        os.kill(self.process.pid, signal.SIGKILL)
        self.process.wait(timeout=30)

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.terminate()
            try:
                self.process.wait(timeout=60)
            except subprocess.TimeoutExpired:
                self.kill()


@pytest.fixture
def service(tmp_path: Path, docker_client: Any) -> Iterator[Service]:
    from orchestrator.project_images import project_image

    project_image("stub")
    project_image("simulator")
    running = Service(tmp_path / "data", tmp_path / "service.log")
    yield running
    running.stop()
    for state in (running.data / "matches").glob("*/pool.json"):  # a match the test left
        from cluster.local import process_start_time

        recorded = json.loads(state.read_text())
        if process_start_time(recorded["pid"]) == recorded.get("start_time"):
            os.kill(recorded["pid"], signal.SIGTERM)


def _token(data: Path) -> str:
    from service.admin import add_team

    engine = make_engine(Settings(data_dir=data).db_url)
    migrate(engine)
    with transaction(session_factory(engine)) as session:
        add_team(session, name="Alpha")
        secret = issue(session, scope=Scope.TEAM, team="Alpha", days=1).secret
    engine.dispose()
    return secret


def _preflight_objects(docker_client: Any) -> list[str]:
    """Names of the containers and networks of pre-flight checks (listed without inspecting
    each: they may go meanwhile)."""
    label = {"label": LABEL_MATCH}
    found = [c["Names"][0].lstrip("/") for c in docker_client.api.containers(all=True,
                                                                              filters=label)
             if (c["Labels"] or {}).get(LABEL_MATCH, "").startswith("preflight-")]
    found += [n["Name"] for n in docker_client.api.networks(filters=label)
              if (n["Labels"] or {}).get(LABEL_MATCH, "").startswith("preflight-")]
    return found


def _wait(predicate: Any, timeout_s: float, what: str) -> Any:
    deadline = time.monotonic() + timeout_s
    while True:
        value = predicate()
        if value:
            return value
        assert time.monotonic() < deadline, f"timed out waiting for {what}"
        time.sleep(0.3)


def test_service_killed_during_a_preflight_and_during_a_match(
        service: Service, docker_client: Any, tmp_path: Path) -> None:
    token = _token(service.data)
    headers = {"Authorization": f"Bearer {token}"}
    service.start()
    with httpx.Client(base_url=service.url, headers=headers, timeout=120) as http:
        # a robot that never connects keeps the check waiting (up to 60 s)
        put = http.put("/v1/team/files/team_config", json=_team_doc("sleep 600"))
        assert put.status_code == 201, put.text
        answers: list[object] = []

        def submit() -> None:
            try:
                answers.append(http.post("/v1/submissions", json={}).status_code)
            except httpx.HTTPError as exc:
                answers.append(type(exc).__name__)

        before = set(Path(tempfile.gettempdir()).glob("hlvs-preflight-*"))
        others = set(_preflight_objects(docker_client))  # other tests' checks on the engine
        asking = threading.Thread(target=submit)
        asking.start()
        _wait(lambda: any(name.endswith("red-1")
                          for name in set(_preflight_objects(docker_client)) - others),
              60, "the pre-flight's robot")
        service.kill()
        asking.join(timeout=30)
    folders = set(Path(tempfile.gettempdir()).glob("hlvs-preflight-*")) - before
    assert folders  # the check's own, left by the killed service
    assert answers and not isinstance(answers[0], int), answers  # no answer: submit again
    left = set(_preflight_objects(docker_client)) - others
    assert left  # what the check left while the service is down

    service.start()
    with httpx.Client(base_url=service.url, headers=headers, timeout=120) as http:
        assert http.get("/v1/submissions").json() == []  # the killed request recorded nothing
        # the killed check's own objects (other tests' pre-flights may run on the engine now)
        _wait(lambda: not left & set(_preflight_objects(docker_client)), 60,
              "the check's leftovers to go")
        _wait(lambda: not any(p.exists() for p in folders), 30, "the check's folder to go")

        put = http.put("/v1/team/files/team_config",
                       json=_team_doc("striker --start-pose -1.0 -3.1 1.57"))
        assert put.status_code == 201, put.text
        created = http.post("/v1/submissions", json={})
        assert created.status_code == 201, created.text
        sid = created.json()["id"]
        running = wait_for_status(http, sid, lambda b: b["state"] == "running", 60)
    work = service.data / "matches" / running["match_id"]
    pid = json.loads((work / "pool.json").read_text())["pid"]
    service.kill()
    os.kill(pid, 0)  # the match plays on without the service

    service.start()
    with httpx.Client(base_url=service.url, headers=headers, timeout=120) as http:
        # two 10 s halves: about a minute at real time; ten on a machine loaded to a real-time
        # factor of 0.1 (seen with the load average at 20 on 2 cores)
        done = wait_for_status(http, sid, lambda b: b["state"] not in ("running", "starting"), 600)
        assert done["state"] == "done", done
        assert done["attempts"] == 1 and done["match_id"] == running["match_id"]
        results = http.get(f"/v1/submissions/{sid}/results")
        assert results.status_code == 200, results.text
        assert results.json()["final_state"] == "FINISHED", results.text
    assert sorted(p.name for p in (service.data / "matches").iterdir()) == [running["match_id"]]
