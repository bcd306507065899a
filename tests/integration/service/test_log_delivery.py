"""A team's logs delivered after its test match to the target of the credentials it uploaded:
real SFTP (asyncssh) and S3 (moto) servers on 127.0.0.1, the served service; the match output
comes from the fake pool (real matches deliver in test_real_matches.py)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import httpx
import pytest

from cluster.fake import FakePool
from service import Settings
from testkit.s3 import MotoServer
from testkit.sftp import AsyncsshServer
from tests.integration.delivery.conftest import (  # noqa: F401 (fixtures)
    asyncssh_server,
    check_manifest,
    moto,
    read_tree,
)
from tests.integration.delivery.test_delivery_s3 import ensure_bucket, read_bucket, s3_body
from tests.integration.delivery.test_delivery_sftp import sftp_body
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import Served, serve
from tests.unit.service.conftest import team_doc, wait_for_status


def play(served: Served, pool: FakePool, http: httpx.Client) -> dict[str, Any]:
    """Submit, let the fake pool finish the match, wait until the delivery has ended."""
    sid = http.post("/v1/submissions", json={}).json()["id"]
    wait_for_status(http, sid, lambda b: b["state"] == "running", 30)
    [handle] = [h for h, m in pool.handles.items() if m.startswith(sid)]
    pool.finish(handle, {"status": "success"})
    return wait_for_status(http, sid, lambda b: b["state"] == "done"
                           and b["log_delivery"] is not None
                           and b["log_delivery"]["state"] != "pending", 30)


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_logs_go_to_the_uploaded_sftp_or_s3_target_and_failures_say_why(
        settings: Settings, make_token: TokenMaker, asyncssh_server: AsyncsshServer,  # noqa: F811
        moto: MotoServer, tmp_path: Path) -> None:  # noqa: F811
    pool = FakePool(slots=3)
    served = serve(settings.with_(worker_poll_s=0.1, match_slots=3, video=False),
                   start_worker=True, pool_factory=lambda _s: pool,
                   preflight=lambda _doc, _s: 0.01)
    ensure_bucket(moto.endpoint_url, moto.admin, "team-logs")
    targets = {
        "Alpha": {"type": "sftp", "credentials": sftp_body(asyncssh_server)},
        "Beta": {"type": "s3", "credentials": s3_body(moto.endpoint_url, moto.admin,
                                                       "team-logs")},
        "Gamma": {"type": "sftp", "credentials": sftp_body(asyncssh_server,
                                                            password="not-the-password")},
    }
    clients = {}
    try:
        for name, credentials in targets.items():
            http = clients[name] = served.client(make_token(team=name))
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
            stored = http.put("/v1/team/files/credentials", json=credentials)
            assert stored.status_code == 201, stored.text
        ended = {name: play(served, pool, http) for name, http in clients.items()}

        alpha = ended["Alpha"]
        assert alpha["log_delivery"]["state"] == "delivered", alpha
        assert "sftp://hlvs@127.0.0.1" in alpha["log_delivery"]["detail"]
        remote = read_tree(asyncssh_server.root / "upload" / "hlvs")
        manifest = check_manifest(remote, f"{alpha['match_id']}/Alpha")
        assert [f["path"] for f in manifest["files"]] == ["1/stdout.log"]
        assert remote[f"{alpha['match_id']}/Alpha/1/stdout.log"] == b"red robot log\n"
        assert not any("blue" in key for key in remote)  # never the other team's logs

        beta = ended["Beta"]
        assert beta["log_delivery"]["state"] == "delivered", beta
        bucket = read_bucket(moto.endpoint_url, moto.admin, "team-logs", "hlvs/2026")
        check_manifest(bucket, f"{beta['match_id']}/Beta")
        assert bucket[f"{beta['match_id']}/Beta/1/stdout.log"] == b"red robot log\n"

        gamma = ended["Gamma"]
        assert gamma["state"] == "done", gamma  # a failed delivery does not fail the match
        assert gamma["log_delivery"]["state"] == "failed"
        assert "(auth:" in gamma["log_delivery"]["detail"], gamma["log_delivery"]
        assert "not-the-password" not in str(gamma)
        assert not any(key.startswith(f"{gamma['match_id']}/")
                       for key in read_tree(asyncssh_server.root / "upload" / "hlvs"))
        # the logs stay downloadable from the service, delivered or not
        for name, body in ended.items():
            own = clients[name].get(f"/v1/submissions/{body['id']}/logs/team/1/stdout.log")
            assert own.status_code == 200 and own.text == "red robot log\n"

        # no credentials uploaded: nothing to deliver
        delta = served.client(make_token(team="Delta"))
        clients["Delta"] = delta
        assert delta.put("/v1/team/files/team_config", json=team_doc("Delta")).status_code == 201
        sid = delta.post("/v1/submissions", json={}).json()["id"]
        wait_for_status(delta, sid, lambda b: b["state"] == "running", 30)
        [handle] = [h for h, m in pool.handles.items() if m.startswith(sid)]
        pool.finish(handle, {"status": "success"})
        done = wait_for_status(delta, sid, lambda b: b["state"] == "done", 30)
        assert done["log_delivery"] is None
    finally:
        for http in clients.values():
            http.close()
        served.stop()
