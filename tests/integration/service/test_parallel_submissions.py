"""Parallel submissions against the served service (SQLite and PostgreSQL), as the attack
made them: twelve teams submitting at once never get a 500, and one team's parallel
submissions run one pre-flight check at a time (a slow registry holds one request thread, not
all of them), while the worker starts matches against the project's stub."""

from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from orchestrator.config import TeamConfig
from service import Settings
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import serve
from tests.unit.service.conftest import team_doc


class SlowPreflight:
    """A pre-flight that takes ``seconds`` (a slow registry), counting the checks running."""

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds
        self.running = 0
        self.most = 0
        self.by_team: dict[str, int] = {}
        self._lock = threading.Lock()

    def __call__(self, team: TeamConfig, settings: Settings) -> float:
        with self._lock:
            self.running += 1
            self.most = max(self.most, self.running)
            self.by_team[team.name] = self.by_team.get(team.name, 0) + 1
        try:
            time.sleep(self.seconds)
        finally:
            with self._lock:
                self.running -= 1
        return self.seconds


def test_twelve_parallel_submissions_never_answer_500(
        settings: Settings, make_token: TokenMaker, monkeypatch: pytest.MonkeyPatch) -> None:
    import service.worker as worker

    pool = FakePool(slots=4)
    preflight = SlowPreflight(0.3)
    real_stub = worker.QueueWorker._stub

    def slow_stub(self: Any) -> str:  # the stub image built when missing: seconds
        if self._stub_image is None:
            time.sleep(3.0)
            self._stub_image = "hlvs-runner/stub:test"
        return str(real_stub(self))

    monkeypatch.setattr(worker.QueueWorker, "_stub", slow_stub)
    served = serve(settings.with_(worker_poll_s=0.05, match_slots=4, video=False, threads=8),
                   start_worker=True, pool_factory=lambda _s: pool, preflight=preflight)
    names = [f"Team{n:02d}" for n in range(12)]
    clients = {name: served.client(make_token(team=name)) for name in names}
    try:
        for name, http in clients.items():
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201

        def submit(name: str) -> httpx.Response:
            return clients[name].post("/v1/submissions", json={})

        def poll(name: str) -> list[int]:
            codes = []
            for _ in range(20):
                codes.append(clients[name].get("/v1/submissions").status_code)
                time.sleep(0.05)
            return codes

        with ThreadPoolExecutor(max_workers=24) as threads:
            first = list(threads.map(submit, names))
            # while the worker starts matches (and finds its stub), everyone keeps polling
            polled = list(threads.map(poll, names))
            again = list(threads.map(submit, names))  # each has an active one now: 409
        assert [r.status_code for r in first] == [201] * 12, [r.text for r in first]
        assert all(code == 200 for codes in polled for code in codes), polled
        assert [r.status_code for r in again] == [409] * 12, [r.text for r in again]
        assert all(r.json()["existing_id"] for r in again)
    finally:
        for http in clients.values():
            http.close()
        served.stop()


def test_one_team_runs_one_preflight_at_a_time_and_others_are_answered_meanwhile(
        settings: Settings, make_token: TokenMaker) -> None:
    pool = FakePool(slots=2)
    preflight = SlowPreflight(3.0)  # a tarpit registry, cut at its deadline
    served = serve(settings.with_(worker_poll_s=0.05, match_slots=2, video=False,
                                  stub_image="hlvs-runner/stub:test", threads=8),
                   start_worker=True, pool_factory=lambda _s: pool, preflight=preflight)
    mallory = served.client(make_token(team="Mallory"))
    honest = served.client(make_token(team="Honest"))
    try:
        for name, http in (("Mallory", mallory), ("Honest", honest)):
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
        with ThreadPoolExecutor(max_workers=8) as threads:
            started = time.monotonic()
            flood = [threads.submit(mallory.post, "/v1/submissions", json={}) for _ in range(8)]
            time.sleep(0.5)
            asked = time.monotonic()
            answer = honest.post("/v1/submissions", json={})
            honest_s = time.monotonic() - asked
            codes = sorted(f.result().status_code for f in flood)
            flood_s = time.monotonic() - started
        assert codes == [201] + [409] * 7, codes
        assert preflight.by_team["Mallory"] == 1
        assert answer.status_code == 201, answer.text
        # Honest waited for its own pre-flight only (3 s), not behind Mallory's eight
        assert honest_s < 3.0 + 2.5, honest_s
        assert flood_s < 3.0 + 2.5, flood_s
    finally:
        mallory.close()
        honest.close()
        served.stop()
