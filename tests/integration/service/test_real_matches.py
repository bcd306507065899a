"""The service with the local Docker pool and the real pre-flight check: real matches on the
engine, a real SMTP server on loopback (aiosmtpd), PostgreSQL and SQLite."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from email import message_from_bytes
from email.message import Message
from pathlib import Path
from typing import Any

import httpx
import pytest

from contracts import files
from service import Settings
from testkit.s3 import MotoServer
from tests.integration.delivery.conftest import check_manifest, moto  # noqa: F401 (fixture)
from tests.integration.delivery.test_delivery_s3 import ensure_bucket, read_bucket, s3_body
from tests.integration.images.conftest import Registry, push, registry  # noqa: F401 (fixture)
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import free_port, serve
from tests.unit.service.conftest import wait_for_status

pytestmark = [pytest.mark.docker, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0, reason="matches need root (host controls)")]

REPO = Path(__file__).parents[3]
EXAMPLE_TEAM = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1" / \
    "team_red.json"


def team_doc(name: str, **player: Any) -> dict[str, Any]:
    doc: dict[str, Any] = json.loads(EXAMPLE_TEAM.read_text())
    doc["name"] = name
    doc["players"]["1"].update(player)
    return doc


class Inbox:
    def __init__(self) -> None:
        self.messages: list[Message] = []

    async def handle_DATA(self, server: Any, session: Any, envelope: Any) -> str:  # noqa: N802
        self.messages.append(message_from_bytes(envelope.content))
        return "250 OK"

    def subjects(self) -> list[str]:
        return [str(m["Subject"]) for m in self.messages]


@pytest.fixture
def inbox() -> Iterator[tuple[Inbox, int]]:
    from aiosmtpd.controller import Controller

    handler = Inbox()
    port = free_port()
    controller = Controller(handler, hostname="127.0.0.1", port=port)
    controller.start()
    yield handler, port
    controller.stop()


@pytest.fixture
def real_settings(settings: Settings, docker_client: Any) -> Settings:
    from orchestrator.project_images import project_image

    project_image("stub")
    project_image("simulator")
    # the service's own test-match timing (contracts.timing.TEST_MATCH: 40 s halves, 10 s READY)
    return settings.with_(worker_poll_s=0.3, test_grace_s=2.0,
                          preflight_timeout_s=25.0, video_width=320, video_height=180,
                          video_fps=2.0,  # 90 s of match: few frames to render
                          log_target_allow="127.0.0.0/8",  # the test's S3 server is local
                          team_project_images=True)  # teams play the project's stub


def _hlvs(*argv: str) -> subprocess.Popen[str]:
    """The ``hlvs`` command a team runs, as a process of its own."""
    return subprocess.Popen([sys.executable, "-m", "hlvs", *argv], cwd=REPO,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _running_submission(http: httpx.Client, submit: subprocess.Popen[str],
                        timeout_s: float) -> str:
    """The id of the team's submission once it runs (``hlvs submit --wait`` still waits)."""
    deadline = time.monotonic() + timeout_s
    while True:
        listed = http.get("/v1/submissions").json()
        if listed and listed[0]["state"] == "running":
            return str(listed[0]["id"])
        assert submit.poll() is None, submit.communicate()
        assert time.monotonic() < deadline, listed
        time.sleep(0.2)


def _finished(process: subprocess.Popen[str], timeout_s: float) -> tuple[int, str, str]:
    try:
        out, err = process.communicate(timeout=timeout_s)
    except subprocess.TimeoutExpired:
        process.kill()
        out, err = process.communicate()
        pytest.fail(f"{process.args[3:5]} still running after {timeout_s} s;\n"
                    f"stdout: {out[-2000:]}\nstderr: {err[-4000:]}")
    return process.returncode, out, err


@pytest.mark.parametrize("db_url", ["postgresql"], indirect=True)
def test_submit_wait_from_a_registry_plays_both_halves_mail_download_and_isolation(
        real_settings: Settings, make_token: TokenMaker, inbox: tuple[Inbox, int],
        moto: MotoServer, registry: Registry, docker_client: Any,  # noqa: F811
        tmp_path: Path) -> None:
    from orchestrator.project_images import project_image

    mails, smtp_port = inbox
    port = free_port()
    settings = real_settings.with_(smtp_host="127.0.0.1", smtp_port=smtp_port,
                                   public_url=f"http://127.0.0.1:{port}")
    # the team pushes its image to its registry; the service pulls it with the team's login
    image = f"{registry.host}/alpha/robot"
    docker_client.images.get(project_image("stub")).tag(image, "v1")
    push(docker_client, f"{image}:v1", "alpha", registry.users["alpha"])
    docker_client.images.remove(f"{image}:v1")
    alpha_team = team_doc("Alpha", dockerTag="v1")
    alpha_team["image"] = image
    alpha_team["registry_auth"] = {"username": "alpha", "password": registry.users["alpha"]}
    team_file = tmp_path / "team_config.json"
    team_file.write_text(json.dumps(alpha_team))
    token_file = tmp_path / "token"
    alpha_token = make_token(team="Alpha", email="alpha@example.org")
    token_file.write_text(alpha_token + "\n")
    common = ["--server", settings.public_url, "--token-file", str(token_file)]

    served = serve(settings, start_worker=True, port=port)
    try:
        alpha = served.client(alpha_token)
        beta = served.client(make_token(team="Beta", email="beta@example.org",
                                        accepts_friendlies=True))
        assert beta.put("/v1/team/files/team_config", json=team_doc("Beta")).status_code == 201
        ensure_bucket(moto.endpoint_url, moto.admin, "alpha-logs")
        target = {"type": "s3", "credentials": s3_body(moto.endpoint_url, moto.admin,
                                                        "alpha-logs")}
        assert alpha.put("/v1/team/files/credentials", json=target).status_code == 201
        # a friendly against Beta (a league match: it moves both teams' ratings)
        submit = _hlvs("submit", *common, "--team-config", str(team_file), "--opponent", "Beta",
                       "--wait", "--poll", "1")
        sid = _running_submission(alpha, submit, 90)
        second = alpha.post("/v1/submissions", json={})
        assert second.status_code == 409 and second.json()["existing_id"] == sid

        # Beta waits behind Alpha's match, then cancels while queued: no charge, no video.
        queued = beta.post("/v1/submissions", json={})
        assert queued.status_code == 201, queued.text
        waiting = queued.json()
        assert waiting["state"] == "queued" and waiting["queue_position"] == 1
        assert "busy" in waiting["waiting_reason"] and waiting["expected_start"]
        cancelled = beta.post(f"/v1/submissions/{waiting['id']}/cancel").json()
        assert cancelled["state"] == "cancelled" and cancelled["charged"] is False
        assert cancelled["video"] is None

        # a test match of two 40 s halves, paced to real time, and its video: minutes on a
        # loaded machine; what the command printed is shown if it never ends
        code, out, err = _finished(submit, 480)
        assert code == 0, err
        done = json.loads(out)
        assert done["id"] == sid and done["state"] == "done", done
        assert "stored as team_config version" in err
        report = alpha.get(f"/v1/submissions/{sid}/report").json()
        assert report["match_report"] == {"status": "success"}
        assert report["backend_error"] is False and set(report["team_robots"]) == {"red-1"}
        results = alpha.get(f"/v1/submissions/{sid}/results").json()
        assert results["final_state"] == "FINISHED"
        play = results["play"]
        assert play["both_halves_playing"] is True, play  # both halves played football
        assert play["playing_s"] >= 40.0, play
        assert sum(play["kicks"].values()) + sum(play["goals"].values()) > 0, play
        robot_log = alpha.get(f"/v1/submissions/{sid}/logs/team/1/robocup-logs/stub_red_1.log")
        assert robot_log.status_code == 200 and robot_log.content
        for path in ("/logs", "/logs/team/1/stdout.log", "/results", "/report", "/video"):
            assert beta.get(f"/v1/submissions/{sid}{path}").status_code == 404, path

        # Alpha's logs went to its S3 bucket after the match
        delivered = wait_for_status(alpha, sid,
                                    lambda b: b["log_delivery"]["state"] != "pending", 60)
        assert delivered["log_delivery"]["state"] == "delivered", delivered["log_delivery"]
        bucket = read_bucket(moto.endpoint_url, moto.admin, "alpha-logs", "hlvs/2026")
        check_manifest(bucket, f"{done['match_id']}/Alpha")
        assert f"{done['match_id']}/Alpha/1/robocup-logs/stub_red_1.log" in bucket

        # the video is rendered after the match ended, outside it; the team downloads it all
        rendered = wait_for_status(alpha, sid, lambda b: b["video"]["state"] != "pending", 180)
        assert rendered["video"]["state"] == "ready", rendered["video"]
        assert "320x180 at 2 fps" in rendered["video"]["detail"]
        code, out, err = _finished(_hlvs("results", *common, sid, "--out",
                                         str(tmp_path / "r")), 60)
        assert code == 0, err
        assert {files.REPORT, files.RESULTS, files.REPLAY, files.VIDEO} <= \
            set(json.loads(out)["files"]), out
        assert (tmp_path / "r" / files.VIDEO).read_bytes()[4:8] == b"ftyp"
        code, out, err = _finished(_hlvs("logs", "fetch", *common, sid, "--out",
                                         str(tmp_path / "l")), 60)
        assert code == 0, err
        assert (tmp_path / "l" / "team" / "1" / "stdout.log").is_file()
        assert not list((tmp_path / "l").rglob("*.partial*"))

        deadline = time.monotonic() + 20
        while len([s for s in mails.subjects() if sid in s]) < 2:
            assert time.monotonic() < deadline, mails.subjects()
            time.sleep(0.2)
        subjects = [s for s in mails.subjects() if sid in s]
        assert subjects == [f"[hlvs] test match {sid} started",
                            f"[hlvs] test match {sid} finished"]
        finished = next(m for m in mails.messages if "finished" in str(m["Subject"]))
        assert finished["To"] == "alpha@example.org"
        text = str(finished.get_payload())
        score = results["score"]
        assert f"score:   you (red) {score['red']} : {score['blue']} Beta" in text
        outcome = {"red": "won", "blue": "lost", "draw": "draw"}[results["winner"]]
        assert f"outcome: {outcome}" in text
        pages = re.findall(r"http://127\.0\.0\.1:\d+/watch/\S+", text)
        assert f"{settings.public_url}/watch/replay/{sid}" in pages, text
        with httpx.Client(timeout=10) as browser:  # no token: the page signs in itself
            for page in pages:
                opened = browser.get(page)
                assert opened.status_code == 200 and "text/html" in \
                    opened.headers["content-type"], page
        # the played friendly is in the league table: both teams rated from its result
        table = {row["team"]: row for row in alpha.get("/v1/ladder").json()["teams"]}
        assert table["Alpha"]["played"] == table["Beta"]["played"] == 1
        assert table["Alpha"]["sigma"] < 8.3 and table["Beta"]["sigma"] < 8.3  # from 25 / 3
        matches = alpha.get("/v1/ladder/Alpha").json()["matches"]
        assert matches[0]["id"] == sid and matches[0]["outcome"] == {
            "won": "won", "lost": "lost", "draw": "drawn"}[outcome]
        alpha.close()
        beta.close()
    finally:
        served.stop()


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_bad_images_are_refused_by_the_preflight_check_with_the_cause(
        real_settings: Settings, make_token: TokenMaker) -> None:
    served = serve(real_settings, start_worker=False)
    try:
        http = served.client(make_token(team="Alpha"))
        unreachable = team_doc("Alpha")
        unreachable["image"] = f"127.0.0.1:{free_port()}/alpha/robot"
        assert http.put("/v1/team/files/team_config", json=unreachable).status_code == 201
        started = time.monotonic()
        answer = http.post("/v1/submissions", json={})
        assert time.monotonic() - started < 30
        assert answer.status_code == 422
        body = answer.json()
        assert body["error"] == "preflight_failed" and body["stage"] == "pull"
        assert "alpha/robot" in body["image"] and body["cause"]

        crashing = team_doc("Alpha", dockerCmd="no-such-role")
        assert http.put("/v1/team/files/team_config", json=crashing).status_code == 201
        started = time.monotonic()
        answer = http.post("/v1/submissions", json={})
        assert time.monotonic() - started < 30
        assert answer.status_code == 422, answer.text
        assert answer.json()["stage"] == "start"
        assert "exited with code" in answer.json()["cause"]
        assert http.get("/v1/submissions").json() == []  # nothing was queued
        http.close()
    finally:
        served.stop()


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_restart_mid_match_then_cancel_running(real_settings: Settings,
                                               make_token: TokenMaker) -> None:
    settings = real_settings.with_(test_half_duration_s=60.0)
    token = make_token(team="Alpha")
    served = serve(settings, start_worker=True)
    with served.client(token) as http:
        assert http.put("/v1/team/files/team_config", json=team_doc("Alpha")).status_code == 201
        sid = http.post("/v1/submissions", json={}).json()["id"]
        running = wait_for_status(http, sid, lambda b: b["state"] == "running", 30)
    served.stop()
    work = settings.matches_dir / running["match_id"]
    pid = json.loads((work / "pool.json").read_text())["pid"]
    os.kill(pid, 0)  # the match goes on without the service

    again = serve(settings, start_worker=True)
    try:
        with again.client(token) as http:
            time.sleep(1.5)  # a few worker rounds
            status = wait_for_status(http, sid, lambda b: b["state"] == "running", 10)
            assert status["attempts"] == 1 and status["match_id"] == running["match_id"]
            assert json.loads((work / "pool.json").read_text())["pid"] == pid
            assert sorted(p.name for p in settings.matches_dir.iterdir()) == [
                running["match_id"]]
            asked = http.post(f"/v1/submissions/{sid}/cancel").json()
            assert asked["cancel_requested"] is True
            ended = wait_for_status(http, sid, lambda b: b["state"] != "running", 90)
            assert ended["state"] == "cancelled", ended
            report = http.get(f"/v1/submissions/{sid}/report").json()
            assert report["match_report"]["failure_class"] == "interrupted"
            assert http.get(f"/v1/submissions/{sid}/logs").json()["team"]  # logs collected
    finally:
        again.stop()
