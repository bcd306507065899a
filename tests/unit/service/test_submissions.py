"""Test-match submissions with a fake pool: queue, one per team, cancel, status, downloads,
team isolation, operators, restart."""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from service import Settings
from tests.integration.service.harness import Served, serve
from tests.unit.service.conftest import team_doc, wait_for_status


def handle_of(served: Served, submission: str) -> str:
    from sqlalchemy import select

    from service.db import Submission, make_engine, session_factory, transaction

    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        row = session.scalar(select(Submission).where(Submission.id == submission))
        assert row is not None and row.pool_handle is not None
        handle = row.pool_handle
    engine.dispose()
    return handle


def setup_team(served: Served, token: str, name: str) -> httpx.Client:
    with served.client(token) as http:
        assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
    return served.client(token)


def test_submit_run_finish_and_download(start: Callable[..., Served], token: Callable[..., str],
                                        pool: FakePool) -> None:
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as http:
        created = http.post("/v1/submissions", json={})
        assert created.status_code == 201, created.text
        sid = created.json()["id"]
        running = wait_for_status(http, sid, lambda b: b["state"] == "running")
        assert running["queue_position"] is None and running["charged"] is True
        second = http.post("/v1/submissions", json={"opponent": "stub"})
        assert second.status_code == 409
        assert second.json()["existing_id"] == sid
        pool.finish(handle_of(served, sid), {"status": "success"})
        done = wait_for_status(http, sid, lambda b: b["state"] == "done")
        assert done["failure_class"] is None
        report = http.get(f"/v1/submissions/{sid}/report").json()
        assert report["status"] == "success" and report["backend_error"] is False
        assert report["match_report"] == {"status": "success"}
        assert report["user_returncode"] == 0 and set(report["team_robots"]) == {"red-1"}
        assert http.get(f"/v1/submissions/{sid}/results").json()["score"] == {"red": 1, "blue": 0}
        logs = http.get(f"/v1/submissions/{sid}/logs").json()
        assert logs == {"team": ["1/stdout.log"], "public": ["referee.log", "replay.hlvsrec"]}
        own = http.get(f"/v1/submissions/{sid}/logs/team/1/stdout.log")
        assert own.status_code == 200 and own.text == "red robot log\n"
        escape = http.get(f"/v1/submissions/{sid}/logs/team/..%2Fblue%2F1%2Fstdout.log")
        assert escape.status_code == 404
        assert http.get(f"/v1/submissions/{sid}/video").status_code == 404
        # a new submission is accepted once the first has ended
        again = http.post("/v1/submissions", json={})
        assert again.status_code == 201
        sid2 = again.json()["id"]
        wait_for_status(http, sid2, lambda b: b["state"] == "running")
    assert pool.started == [f"{sid}-a1", f"{sid2}-a1"]


def test_other_teams_ids_are_not_found(start: Callable[..., Served],
                                       token: Callable[..., str]) -> None:
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as alpha, \
            setup_team(served, token("Beta"), "Beta") as beta:
        sid = alpha.post("/v1/submissions", json={}).json()["id"]
        for path in ("", "/report", "/results", "/logs", "/logs/team/1/stdout.log", "/replay"):
            answer = beta.get(f"/v1/submissions/{sid}{path}")
            assert answer.status_code == 404, path
            unknown = beta.get(f"/v1/submissions/sub_000000000000{path}")
            assert unknown.status_code == 404
            assert answer.json()["error"] == unknown.json()["error"] == "not_found"
        assert beta.post(f"/v1/submissions/{sid}/cancel").status_code == 404
        assert alpha.get(f"/v1/submissions/{sid}").status_code == 200


def test_cancel_queued_is_free_and_cancel_running_stops_the_match(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    served = start()
    operator = served.client(token(operator=True))
    assert operator.post("/v1/operator/queue/pause").json()["paused"] is True
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        queued = http.get(f"/v1/submissions/{sid}").json()
        assert queued["state"] == "queued" and queued["queue_position"] == 1
        assert "paused" in queued["waiting_reason"]
        cancelled = http.post(f"/v1/submissions/{sid}/cancel").json()
        assert cancelled["state"] == "cancelled" and cancelled["charged"] is False
        again = http.post(f"/v1/submissions/{sid}/cancel")
        assert again.status_code == 409
        operator.post("/v1/operator/queue/resume")
        sid2 = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid2, lambda b: b["state"] == "running")
        asked = http.post(f"/v1/submissions/{sid2}/cancel").json()
        assert asked["cancel_requested"] is True
        ended = wait_for_status(http, sid2, lambda b: b["state"] == "cancelled")
        assert "gracefully" in ended["cause"]
        assert pool.cancelled == [handle_of(served, sid2)]
    operator.close()


def test_queue_position_expected_start_and_reason(start: Callable[..., Served],
                                                  token: Callable[..., str]) -> None:
    served = start(expected_match_s=600.0)
    clients = [setup_team(served, token(name), name) for name in ("A1", "B2", "C3")]
    ids = [c.post("/v1/submissions", json={}).json()["id"] for c in clients]
    wait_for_status(clients[0], ids[0], lambda b: b["state"] == "running")
    second = clients[1].get(f"/v1/submissions/{ids[1]}").json()
    third = clients[2].get(f"/v1/submissions/{ids[2]}").json()
    assert (second["queue_position"], third["queue_position"]) == (1, 2)
    assert "all 1 match slot(s) busy" in second["waiting_reason"]
    assert "1 submission(s) ahead" in third["waiting_reason"]
    from datetime import datetime

    gap = (datetime.fromisoformat(third["expected_start"])
           - datetime.fromisoformat(second["expected_start"])).total_seconds()
    assert abs(gap - 600.0) < 1.0
    for c in clients:
        c.close()


def test_restart_mid_match_neither_loses_nor_duplicates(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    served = start()
    tok = token("Alpha")
    with setup_team(served, tok, "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
    served.stop()
    again = start()
    with again.client(tok) as http:
        status = wait_for_status(http, sid, lambda b: b["state"] == "running")
        assert status["attempts"] == 1
        assert pool.started == [f"{sid}-a1"]  # adopted, not started twice
        pool.lose(handle_of(again, sid))  # the match process died with the host
        back = wait_for_status(http, sid, lambda b: b["attempts"] == 2 and b["state"] == "running")
        assert back["match_id"] == f"{sid}-a2"
        assert pool.started == [f"{sid}-a1", f"{sid}-a2"]


def test_operator_requeues_only_league_failures(start: Callable[..., Served],
                                                token: Callable[..., str],
                                                pool: FakePool) -> None:
    served = start()
    operator = served.client(token(operator=True))
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        pool.finish(handle_of(served, sid), {"status": "failed", "failure_class": "simulator",
                                             "cause": "simulator exited with code 139"})
        failed = wait_for_status(http, sid, lambda b: b["state"] == "failed")
        assert failed["failure_side"] == "league" and failed["charged"] is False
        report = http.get(f"/v1/submissions/{sid}/report").json()
        assert report["backend_error"] is True and report["failure_class"] == "simulator"
        assert http.post(f"/v1/operator/submissions/{sid}/requeue").status_code == 401
        requeued = operator.post(f"/v1/operator/submissions/{sid}/requeue")
        assert requeued.status_code == 200, requeued.text
        rerun = wait_for_status(http, sid, lambda b: b["state"] == "running" and b["attempts"] == 2)
        pool.finish(handle_of(served, sid), {"status": "failed", "failure_class": "team_crash",
                                             "cause": "robots broke the match"})
        team_fault = wait_for_status(http, sid, lambda b: b["state"] == "failed")
        assert team_fault["failure_side"] == "team" and rerun["charged"] is True
        refused = operator.post(f"/v1/operator/submissions/{sid}/requeue")
        assert refused.status_code == 409
        queue = operator.get("/v1/operator/queue").json()
        assert queue["paused"] is False and queue["active"] == []
    operator.close()


def test_bad_submissions(start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start()
    with served.client(token("Alpha")) as http:
        none_yet = http.post("/v1/submissions", json={})
        assert none_yet.status_code == 404
        assert "team_config.json" in none_yet.json()["message"]
        bad = team_doc(image="127.0.0.1:1/bad/image")
        assert http.put("/v1/team/files/team_config", json=bad).status_code == 201
        refused = http.post("/v1/submissions", json={})
        assert refused.status_code == 422
        assert refused.json()["stage"] == "pull" and refused.json()["cause"]
        unknown = http.post("/v1/submissions", json={"opponent": "Nobody"})
        assert unknown.status_code == 422 and "stub" in unknown.json()["message"]
        extra = http.post("/v1/submissions", json={"opponent": "stub", "priority": 1})
        assert extra.status_code == 422
        assert extra.json()["problems"][0]["pointer"] == "/priority"
        huge = http.post("/v1/submissions", json={"opponent": "stub" * 10_000})
        assert huge.status_code == 413 and "20000 bytes" in huge.json()["message"]
        not_json = http.post("/v1/submissions", content=b"opponent=stub",
                             headers={"Content-Type": "application/x-www-form-urlencoded"})
        assert not_json.status_code == 422
        assert http.get("/v1/submissions").json() == []


def test_operators_read_the_tournament_schedule_and_standings(
        start: Callable[..., Served], token: Callable[..., str], tmp_path: Path) -> None:
    from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, write_schedule
    from tournament import run_schedule

    schedule = write_schedule(
        tmp_path, COMPRESSED + "fixtures:\n  round_robin: {teams: [alpha, bravo, charlie], "
        "first_stream: '+4s', interval_s: 0.5, stream_length_s: 0.3}\n")
    state = tmp_path / "state.sqlite"
    assert run_schedule(schedule, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    served = start(schedule_state=str(state))
    with served.client(token(operator=True)) as http:
        body = http.get("/v1/operator/schedule").json()
        assert {m["id"] for m in body["matches"]} == {"rr-1", "rr-2", "rr-3"}
        assert {"alpha", "bravo", "charlie"} <= {s["team"] for s in body["standings"]}
        assert sum(s["played"] for s in body["standings"]) == 6
    with served.client(token("Alpha")) as http:
        assert http.get("/v1/operator/schedule").status_code == 401


def test_simultaneous_submissions_of_one_team_queue_exactly_one(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    from concurrent.futures import ThreadPoolExecutor

    served = start()
    operator = served.client(token(operator=True))
    operator.post("/v1/operator/queue/pause")
    tok = token("Alpha")
    setup_team(served, tok, "Alpha").close()

    def submit(_: int) -> httpx.Response:
        with served.client(tok) as http:
            return http.post("/v1/submissions", json={})

    with ThreadPoolExecutor(8) as pool:
        answers = list(pool.map(submit, range(8)))
    codes = sorted(a.status_code for a in answers)
    assert codes == [201] + [409] * 7, [a.text for a in answers]
    created = next(a.json()["id"] for a in answers if a.status_code == 201)
    assert {a.json()["existing_id"] for a in answers if a.status_code == 409} == {created}
    operator.close()


def test_a_start_interrupted_by_a_restart_is_submitted_once(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    """STARTING was committed but the pool was never asked (the service died in between)."""
    from sqlalchemy import select

    from service.db import Submission, make_engine, session_factory, transaction

    served = start()
    operator = served.client(token(operator=True))
    operator.post("/v1/operator/queue/pause")
    tok = token("Alpha")
    with setup_team(served, tok, "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
    served.stop()
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        row = session.scalar(select(Submission).where(Submission.id == sid))
        assert row is not None
        row.state, row.attempts, row.match_id = "starting", 1, f"{sid}-a1"
    engine.dispose()
    again = start()
    with again.client(tok) as http:
        status = wait_for_status(http, sid, lambda b: b["state"] == "running")
        assert status["attempts"] == 1 and status["match_id"] == f"{sid}-a1"
    assert pool.started == [f"{sid}-a1"]
    operator.close()


def test_status_polls_from_memory_follow_changes_and_revocations(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    """Polls answered from the status board and the token cache (no database) still see a
    cancel at once, never another team's submission, and a revoked token within a rebuild."""
    from service.db import Token, make_engine, now, session_factory, transaction

    served = start(token_cache_s=60.0, status_board_s=0.2)
    operator = served.client(token(operator=True))
    operator.post("/v1/operator/queue/pause")
    secret = token("Alpha")
    alpha = setup_team(served, secret, "Alpha")
    beta = setup_team(served, token("Beta"), "Beta")
    sid = alpha.post("/v1/submissions", json={}).json()["id"]
    other = beta.post("/v1/submissions", json={}).json()["id"]
    time.sleep(0.6)  # a few rebuilds: both submissions are on the board
    first = alpha.get(f"/v1/submissions/{sid}")
    assert first.status_code == 200 and first.headers["content-type"] == "application/json"
    assert first.json()["state"] == "queued" and first.json()["queue_position"] == 1
    assert alpha.get(f"/v1/submissions/{other}").status_code == 404  # on the board, not theirs
    assert beta.get(f"/v1/submissions/{other}").json()["queue_position"] == 2
    assert alpha.post(f"/v1/submissions/{sid}/cancel").json()["state"] == "cancelled"
    assert alpha.get(f"/v1/submissions/{sid}").json()["state"] == "cancelled"  # at once
    again = alpha.post("/v1/submissions", json={}).json()["id"]
    assert alpha.get(f"/v1/submissions/{again}").json()["state"] == "queued"
    time.sleep(0.6)
    assert alpha.get(f"/v1/submissions/{again}").json()["queue_position"] == 2

    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        session.get(Token, secret.split("_")[1]).revoked_at = now()  # type: ignore[union-attr]
    engine.dispose()
    deadline = time.monotonic() + 5  # well within the 60 s of the token cache
    while (answer := alpha.get(f"/v1/submissions/{again}")).status_code == 200:
        assert time.monotonic() < deadline, "the revoked token is still accepted"
        time.sleep(0.05)
    assert answer.status_code == 401 and "revoked" in answer.json()["message"]
    for http in (operator, alpha, beta):
        http.close()


def test_a_failed_video_render_leaves_the_match_done(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    """The video is rendered by hlvs render after the match; the fake pool's replay is not a
    real one, so the render fails: the status says why and the submission stays done."""
    served = start(video=True)
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        assert http.get(f"/v1/submissions/{sid}").json()["video"] is None
        pool.finish(handle_of(served, sid), {"status": "success"})
        done = wait_for_status(http, sid, lambda b: b["state"] == "done")
        assert done["video"]["state"] in ("pending", "failed")
        ended = wait_for_status(http, sid, lambda b: b["video"]["state"] != "pending", 60)
        assert ended["state"] == "done" and ended["video"]["state"] == "failed", ended
        assert "hlvs render exited with code 2" in ended["video"]["detail"]
        assert "replay" in ended["video"]["detail"]
        video = http.get(f"/v1/submissions/{sid}/video")
        assert video.status_code == 404 and "video failed" in video.json()["message"]


def test_slurm_account_names_are_per_team_and_slurm_safe() -> None:
    from service.accounts import account_name

    assert account_name(7, "Red Robots") == "hlvs_t7_red_robots"
    assert account_name(8, "Red.Robots") == "hlvs_t8_red_robots"  # the id keeps them apart
    assert account_name(9, "..") == "hlvs_t9"
    assert len(account_name(10, "x" * 64)) <= 40


def test_a_render_left_by_an_earlier_service_process_is_waited_for(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    """render.json names a render that still runs (started before a restart): the video stays
    pending until it ends; then, no video being there, it is rendered again (and here fails:
    the fake pool's replay is not a real one)."""
    import json
    import subprocess

    from cluster.local import process_start_time

    served = start(video=True)
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        running = wait_for_status(http, sid, lambda b: b["state"] == "running")
        work = (served.settings.matches_dir / running["match_id"]).resolve()
        earlier = subprocess.Popen(["sleep", "60"])
        try:
            (work / "render.json").write_text(json.dumps({
                "pid": earlier.pid, "start_time": process_start_time(earlier.pid),
                "renders": 1}))
            pool.finish(handle_of(served, sid), {"status": "success"})
            wait_for_status(http, sid, lambda b: b["state"] == "done")
            time.sleep(1.5)  # rounds of the after-match thread
            assert http.get(f"/v1/submissions/{sid}").json()["video"]["state"] == "pending"
        finally:
            earlier.kill()
            earlier.wait()
        ended = wait_for_status(http, sid, lambda b: b["video"]["state"] != "pending", 60)
        assert ended["video"]["state"] == "failed", ended["video"]
        assert "hlvs render exited with code 2" in ended["video"]["detail"]
        assert json.loads((work / "render.json").read_text())["renders"] == 2


class _Runner:
    """A match runner whose robots have all connected at once (the pre-flight's view)."""

    plans: list[Any] = []

    def __init__(self, plan: Any, **_: Any) -> None:
        from orchestrator.match import EventStream

        self.plans.append(plan)
        self.events = EventStream()
        self.stop_event = threading.Event()

    def run(self) -> None:
        from orchestrator.match import AllConnected

        self.events.publish(AllConnected(bringup_s=0.1))
        self.stop_event.wait(5)


def test_a_submissions_team_file_is_parsed_once(settings: Settings, token: Callable[..., str],
                                                pool: FakePool,
                                                monkeypatch: pytest.MonkeyPatch) -> None:
    """From the request to the pool: the submitted team file is validated once (the upload's
    rules); the full pre-flight (its match machinery faked) and the match files use that
    validated team."""
    import orchestrator.engine
    import orchestrator.engine.containers
    import orchestrator.match
    import orchestrator.project_images
    import orchestrator.pull
    from service import preflight

    monkeypatch.setattr(orchestrator.pull, "resolve_team_images", lambda *a, **k: {})
    monkeypatch.setattr(orchestrator.engine, "connect", lambda: object())
    monkeypatch.setattr(orchestrator.engine.containers, "DockerRuntime", lambda engine: engine)
    monkeypatch.setattr(orchestrator.match.HostControl, "for_current_user",
                        staticmethod(lambda: None))
    monkeypatch.setattr(orchestrator.match, "MatchRunner", _Runner)
    monkeypatch.setattr(orchestrator.match, "cleanup", lambda *a, **k: None)
    monkeypatch.setattr(orchestrator.match, "clean_match", lambda *a, **k: None)
    monkeypatch.setattr(orchestrator.project_images, "project_image",
                        lambda name: f"hlvs-runner/{name}:test")
    served = serve(settings.with_(preflight="full"), start_worker=True,
                   pool_factory=lambda _s: pool,
                   preflight=lambda team, current: preflight.run(team, settings=current))
    try:
        _count_parses(served, token, monkeypatch)
    finally:
        served.stop()
    assert len(pool.started) == 1


def _count_parses(served: Served, token: Callable[..., str],
                  monkeypatch: pytest.MonkeyPatch) -> None:
    from orchestrator.config import loader

    with served.client(token("Alpha")) as http:
        # a team's own image (the project's hlvs-runner/ images fail a team's pre-flight)
        own = team_doc("Alpha", image="registry.example.org/alpha/robot")
        assert http.put("/v1/team/files/team_config", json=own).status_code == 201
        parsed: list[object] = []
        build_team = loader.build_team

        def counted(document: Any, *args: Any, **kwargs: Any) -> Any:
            parsed.append(document.get("name") if isinstance(document, dict) else None)
            return build_team(document, *args, **kwargs)

        monkeypatch.setattr(loader, "build_team", counted)
        created = http.post("/v1/submissions", json={})
        assert created.status_code == 201, created.text
        wait_for_status(http, created.json()["id"], lambda b: b["state"] == "running")
    assert parsed.count("Alpha") == 1
    assert [plan.red.name for plan in _Runner.plans] == ["Alpha"]


def test_a_report_with_cut_logs_is_served(start: Callable[..., Served],
                                          token: Callable[..., str], pool: FakePool) -> None:
    """report.json names the logs cut at their size limit (a list): the report answers it."""
    served = start()
    with setup_team(served, token("Alpha"), "Alpha") as http:
        sid = http.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(http, sid, lambda b: b["state"] == "running")
        cut = [{"robot": "red-1", "what": "log folder", "reason": "above 10 GB"}]
        pool.finish(handle_of(served, sid), {"status": "success", "logs_cut": cut})
        wait_for_status(http, sid, lambda b: b["state"] == "done")
        answer = http.get(f"/v1/submissions/{sid}/report")
        assert answer.status_code == 200, answer.text
        assert answer.json()["match_report"] == {"status": "success", "logs_cut": cut}
