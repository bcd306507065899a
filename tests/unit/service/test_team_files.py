"""Team files over HTTP: checked like hlvs check, kept in versions, bad input refused."""

from __future__ import annotations

import json
from collections.abc import Callable

from tests.integration.service.harness import Served
from tests.unit.service.conftest import team_doc


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
