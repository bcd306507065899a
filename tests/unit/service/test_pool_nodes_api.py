"""``GET /v1/operator/nodes``: operators only; each node's job names its submission and teams."""

from __future__ import annotations

from collections.abc import Callable

from cluster import PoolNode
from cluster.errors import PoolError
from cluster.fake import FakePool
from tests.integration.service.harness import Served
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_submissions import setup_team


def test_operators_see_the_nodes_and_the_submission_on_each(
    start: Callable[..., Served], token: Callable[..., str],
) -> None:
    served = start()
    team = setup_team(served, token("Alpha"), "Alpha")
    sid = team.post("/v1/submissions", json={}).json()["id"]
    body = wait_for_status(team, sid, lambda b: b["state"] == "running")
    refused = team.get("/v1/operator/nodes")  # a team's token is not an operator's
    assert refused.status_code == 401 and "operator" in refused.text, refused.text
    with served.client() as anonymous:
        assert anonymous.get("/v1/operator/nodes").status_code == 401
    with served.client(token(operator=True)) as operator:
        answer = operator.get("/v1/operator/nodes")
        assert answer.status_code == 200, answer.text
        view = answer.json()
    assert (view["pool"], view["slots"]) == ("local", 1)
    (node,) = view["nodes"]
    assert (node["name"], node["state"], node["memory_mb"], node["slots"]) == \
        ("fake-node", "up", 1024, 1)
    assert node["jobs"] == [{"job_id": "fake-0", "state": "running",
                             "match_id": body["match_id"], "submission_id": sid,
                             "team": "Alpha", "opponent": "stub"}]
    team.close()


def test_a_pool_that_does_not_answer_is_a_503_naming_why(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    def down() -> list[PoolNode]:
        raise PoolError(handle="sinfo", reason="sinfo -N: exit 1: Unable to contact slurm "
                        "controller")

    pool.nodes = down  # type: ignore[method-assign]
    served = start()
    with served.client(token(operator=True)) as operator:
        answer = operator.get("/v1/operator/nodes")
    assert answer.status_code == 503 and answer.json()["error"] == "pool_unavailable"
    assert answer.json()["reason"] == "sinfo -N: exit 1: Unable to contact slurm controller"
