"""The submission service on the Slurm pool (the real cluster of scripts/ensure-slurm.sh): a team
added with ``hlvs admin team add`` gets its own Slurm account (GrpJobs=1, a bounded
MaxSubmitJobs); its test match is submitted under that account, and while the account's quota
is taken (by another job of the team) the status gives Slurm's reason; a cancel while Slurm
keeps it waiting costs nothing."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from cluster.slurm import SlurmPool
from service import Settings
from service.db import Scope, make_engine, migrate, session_factory, transaction
from service.tokens import issue
from tests.integration.service.harness import serve
from tests.unit.service.conftest import wait_for_status

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.slow]

EXAMPLE_TEAM = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1" / \
    "team_red.json"


def slurm(cluster: str, *args: str) -> str:
    return subprocess.run(list(args), capture_output=True, text=True, check=True, timeout=60,
                          env={**os.environ, "SLURM_CONF": cluster}).stdout


def test_team_matches_run_under_its_account_and_wait_with_slurms_reason(
        cluster: str, tmp_path: Path, docker_client: Any) -> None:
    from orchestrator.project_images import project_image

    name = f"Alpha {os.getpid()}"
    settings = Settings(data_dir=tmp_path / "data", pool="slurm", slurm_conf=cluster,
                        preflight="images", worker_poll_s=0.5, video=False,
                        slurm_max_queued=3,
                        team_project_images=True)  # the teams play the project's stub
    env = {**os.environ, "HLVS_SERVICE_POOL": "slurm", "HLVS_SERVICE_SLURM_CONF": cluster,
           "HLVS_SERVICE_DATA_DIR": str(settings.data_dir),
           "HLVS_SERVICE_TEAM_PROJECT_IMAGES": "1",
           "HLVS_SERVICE_SLURM_MAX_QUEUED": "3"}
    added = subprocess.run([sys.executable, "-m", "hlvs", "admin", "team", "add", name],
                           env=env, capture_output=True, text=True, timeout=120, check=False)
    assert added.returncode == 0, added.stderr
    account = json.loads(added.stdout)["slurm_account"]
    assert account == f"hlvs_t1_alpha_{os.getpid()}"
    limits = slurm(cluster, "sacctmgr", "-n", "-P", "show", "assoc", f"account={account}",
                   "format=Account,GrpJobs,MaxSubmitJobs")
    assert f"{account}|1|3" in limits.splitlines(), limits

    # another job of the team (its official match, say) holds the account's one running job
    blocker = slurm(cluster, "sbatch", "--parsable", f"--account={account}", "-N1",
                    "--job-name=hlvs-quota-holder", "--output=/dev/null",
                    "--wrap=sleep 600").strip().split(";")[0]
    served = None
    try:
        deadline = time.monotonic() + 60
        while "RUNNING" not in slurm(cluster, "squeue", "-h", "-j", blocker, "-o", "%T"):
            assert time.monotonic() < deadline, "the quota holder never ran"
            time.sleep(0.5)
        engine = make_engine(settings.db_url)
        migrate(engine)
        with transaction(session_factory(engine)) as session:
            token = issue(session, scope=Scope.TEAM, team=name, days=1).secret
        engine.dispose()
        served = serve(settings, start_worker=True)  # the service's own Slurm pool
        stub = project_image("stub")
        doc = json.loads(EXAMPLE_TEAM.read_text())
        doc["name"] = name
        doc["image"], _, doc["players"]["1"]["dockerTag"] = stub.rpartition(":")
        with served.client(token) as http:
            assert http.put("/v1/team/files/team_config", json=doc).status_code == 201
            created = http.post("/v1/submissions", json={})
            assert created.status_code == 201, created.text
            sid = created.json()["id"]
            waiting = wait_for_status(http, sid, lambda b: "AssocGrpJobsLimit" in str(
                b["waiting_reason"]), 60)
            assert waiting["state"] == "starting" and waiting["charged"] is False
            assert waiting["queue_position"] is None
            assert waiting["waiting_reason"].startswith("waiting in Slurm: AssocGrpJobsLimit")
            [entry] = [e for e in SlurmPool(slurm_conf=cluster).queue()
                       if e.name == f"hlvs-{waiting['match_id']}"]
            assert entry.account == account and entry.state == "PENDING"

            asked = http.post(f"/v1/submissions/{sid}/cancel").json()
            assert asked["cancel_requested"] is True
            ended = wait_for_status(http, sid, lambda b: b["state"] != "starting", 60)
            assert ended["state"] == "cancelled" and ended["charged"] is False, ended
            assert ended["waiting_reason"] is None
    finally:
        if served is not None:
            served.stop()
        slurm(cluster, "scancel", blocker)
