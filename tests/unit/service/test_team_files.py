"""Team files over HTTP: checked like hlvs check, kept in versions, bad input refused."""

from __future__ import annotations

import json
from collections.abc import Callable

from cluster.fake import FakePool
from tests.integration.service.harness import Served
from tests.unit.service.conftest import team_doc, wait_for_status
from tests.unit.service.test_submissions import handle_of, setup_team


def test_upload_check_and_versions(start: Callable[..., Served],
                                   token: Callable[..., str]) -> None:
    served = start()
    with served.client(token("Alpha")) as http:
        first = http.put("/v1/team/files/team_config", json=team_doc())
        assert first.status_code == 201, first.text
        assert first.json()["version"] == 1
        changed = team_doc()
        changed["players"]["1"]["dockerTag"] = "v2"
        second = http.put("/v1/team/files/team_config", json=changed)
        assert second.json()["version"] == 2
        versions = http.get("/v1/team/files/team_config").json()
        assert [v["version"] for v in versions] == [1, 2]
        old = http.get("/v1/team/files/team_config/1").json()
        assert old["content"]["players"]["1"]["dockerTag"] == "latest"


def test_invalid_files_get_precise_problems_and_change_nothing(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start()
    with served.client(token("Alpha")) as http:
        assert http.put("/v1/team/files/team_config", json=team_doc()).status_code == 201
        bad = team_doc()
        bad["players"]["1"]["halfTimeStartingPose"]["translation"] = "left"
        bad["colour"] = "red"
        answer = http.put("/v1/team/files/team_config", json=bad)
        assert answer.status_code == 422
        problems = answer.json()["problems"]
        pointers = {p["pointer"] for p in problems}
        assert "/players/1/halfTimeStartingPose/translation" in pointers
        assert all(p["file"] == "team_config.json" for p in problems)
        assert not any("/tmp" in p["text"] for p in problems)

        broken = http.put("/v1/team/files/team_config", content=b'{"name": "x",,}',
                          headers={"Content-Type": "application/json"})
        assert broken.status_code == 422
        assert "line 1 column" in broken.json()["message"]

        wrong_type = http.put("/v1/team/files/team_config", content=json.dumps(team_doc()),
                              headers={"Content-Type": "text/plain"})
        assert wrong_type.status_code == 415
        assert "application/json" in wrong_type.json()["message"]

        huge = team_doc()
        huge["padding"] = "x" * 50_000
        too_big = http.put("/v1/team/files/team_config", json=huge)
        assert too_big.status_code == 413
        assert "20000 bytes" in too_big.json()["message"]

        unknown_kind = http.put("/v1/team/files/secrets", json={})
        assert unknown_kind.status_code == 404

        versions = http.get("/v1/team/files/team_config").json()
        assert [v["version"] for v in versions] == [1]  # nothing stored, nothing lost

        checked = http.post("/v1/team/files/team_config/check", json=bad).json()
        assert checked["valid"] is False and checked["problems"]


def test_team_settings_refuse_unknown_fields(start: Callable[..., Served],
                                             token: Callable[..., str]) -> None:
    served = start()
    with served.client(token("Alpha")) as http:
        answer = http.patch("/v1/team", json={"emial": "a@example.org"})
        assert answer.status_code == 422
        assert answer.json()["problems"][0]["pointer"] == "/emial"
        ok = http.patch("/v1/team", json={"email": "a@example.org"})
        assert ok.status_code == 200 and ok.json()["email"] == "a@example.org"


def test_credentials_are_checked_stored_and_shown_masked(start: Callable[..., Served],
                                                         token: Callable[..., str]) -> None:
    from pathlib import Path

    example = Path(__file__).parents[3] / "configs" / "examples" / "credentials" / "s3.json"
    document = json.loads(example.read_text())
    served = start()
    with served.client(token("Alpha")) as http:
        stored = http.put("/v1/team/files/credentials", json=document)
        assert stored.status_code == 201, stored.text
        shown = http.get("/v1/team/files/credentials/1").json()["content"]
        assert shown["credentials"]["access_secret"] == "***"
        assert shown["credentials"]["bucket"] == document["credentials"]["bucket"]
        broken = {"type": "s3", "credentials": {"access_id": "x"}}
        refused = http.put("/v1/team/files/credentials", json=broken)
        assert refused.status_code == 422
        assert any(p["file"] == "credentials.json" for p in refused.json()["problems"])


def test_only_a_file_whose_preflight_passed_is_played_by_others_and_a_refused_one_is_kept(
        start: Callable[..., Served], token: Callable[..., str], pool: FakePool) -> None:
    """As found: a new upload was the team's current file at once, before (and whatever) its
    pre-flight, and a problem of the file that only the pre-flight found left it current."""
    served = start()
    alpha = setup_team(served, token("Alpha", accepts_friendlies=True), "Alpha")
    beta = setup_team(served, token("Beta", accepts_friendlies=True), "Beta")
    first = alpha.post("/v1/submissions", json={})  # version 1 passes its pre-flight
    assert first.status_code == 201, first.text
    wait_for_status(alpha, first.json()["id"], lambda b: b["state"] == "running")
    pool.finish(handle_of(served, first.json()["id"]), {"status": "success"})
    wait_for_status(alpha, first.json()["id"], lambda b: b["state"] == "done")
    unchecked = team_doc("Alpha", image="127.0.0.1:1/bad/image")
    assert alpha.put("/v1/team/files/team_config", json=unchecked).status_code == 201
    friendly = beta.post("/v1/submissions", json={"opponent": "Alpha"})
    assert friendly.status_code == 201, friendly.text
    sid = friendly.json()["id"]
    wait_for_status(beta, sid, lambda b: b["state"] == "running")
    blue = json.loads(next(served.settings.matches_dir.glob(f"{sid}-a1"))
                      .joinpath("config", "team_blue.json").read_text())
    assert blue["image"] == team_doc("Alpha")["image"], blue["image"]  # version 1, checked
    pool.finish(handle_of(served, sid), {"status": "success"})
    wait_for_status(beta, sid, lambda b: b["state"] == "done")
    # a problem of the file that only the pre-flight finds: refused, kept with its failure
    assert alpha.put("/v1/team/files/team_config",
                     json=team_doc("Alpha", image="league/unfit")).status_code == 201
    refused = alpha.post("/v1/submissions", json={})
    assert refused.status_code == 422, refused.text
    versions = {v["version"]: v for v in alpha.get("/v1/team/files/team_config").json()}
    assert versions[3]["valid"] is False, versions[3]
    assert "pre-flight check failed at config" in versions[3]["problems"][-1]["text"]
    assert "unfit for the match" in versions[3]["problems"][-1]["text"]
    assert alpha.get("/v1/team/files/team_config/3").status_code == 200  # still in the history
