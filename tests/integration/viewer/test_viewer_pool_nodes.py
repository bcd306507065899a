"""The pool page of a real ``hlvs serve`` on the real Slurm cluster, in Chromium: every node that
``sinfo`` lists, a drained node with its reason, a match job on its node; the page refreshes by
itself when the job ends and the node comes back."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
import uuid
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest

from cluster.slurm import SlurmPool
from tests.integration.pool.conftest import cluster  # noqa: F401
from tests.integration.service.harness import Served, serve
from tests.integration.viewer.conftest import screenshot
from tests.unit.service.conftest import settings, token  # noqa: F401

pytestmark = [pytest.mark.root, pytest.mark.browser]


def _slurm(conf: str, *args: str) -> str:
    result = subprocess.run(list(args), capture_output=True, text=True, timeout=60, check=False,
                            env={**os.environ, "SLURM_CONF": conf})
    assert result.returncode == 0, (args, result.stderr)
    return result.stdout


@pytest.fixture
def served_slurm(cluster: str, settings: Any) -> Iterator[Served]:  # noqa: F811
    served = serve(settings.with_(pool="slurm"),
                   pool_factory=lambda s: SlurmPool(slots=2, slurm_conf=cluster))
    yield served
    served.stop()


def _rows(page: Any) -> dict[str, list[str]]:  # noqa: F811
    rows: list[list[str]] = page.locator("[data-testid=nodes] tr").evaluate_all(
        "rows => rows.slice(1).map(r => Array.from(r.cells).map(c => c.innerText))")
    return {r[0]: r for r in rows}


def _until(predicate: Callable[[], bool], what: str, timeout_s: float = 40) -> None:
    deadline = time.monotonic() + timeout_s
    while not predicate():
        assert time.monotonic() < deadline, what
        time.sleep(0.3)


def test_the_pool_page_lists_slurm_nodes_their_state_and_the_match_on_each(
    cluster: str, served_slurm: Served, token: Callable[..., str], page: Any,  # noqa: F811
    tmp_path: Path,
) -> None:
    match_id = f"nodes-page-{uuid.uuid4().hex[:8]}"
    job = _slurm(cluster, "sbatch", "--parsable", "--exclusive", "-N1",
                 f"--job-name=hlvs-{match_id}", f"--chdir={tmp_path}", "--output=/dev/null",
                 "--wrap", "sleep 300").strip().split(";")[0]
    drained: str | None = None
    reason = f"pool page test {match_id}"
    try:
        _until(lambda: _slurm(cluster, "squeue", "-h", "-j", job, "-o", "%T").strip()
               == "RUNNING", f"job {job} running", timeout_s=180)
        on = _slurm(cluster, "squeue", "-h", "-j", job, "-o", "%N").strip()
        listed = _slurm(cluster, "sinfo", "-N", "-h", "-o", "%N %T").split()
        names, states = listed[0::2], dict(zip(listed[0::2], listed[1::2], strict=True))
        idle = [n for n in names if states[n] == "idle" and n != on]
        if idle:
            drained = idle[-1]
            _slurm(cluster, "scontrol", "update", f"nodename={drained}", "state=drain",
                   f"reason={reason}")

        page.goto(f"{served_slurm.url}/watch/")
        page.locator("[data-testid=token]").fill(token(operator=True))
        page.locator("[data-testid=sign-in]").click()
        page.wait_for_selector("[data-testid=who]")  # signed in for this browser session
        page.goto(f"{served_slurm.url}/watch/nodes")
        page.wait_for_selector("[data-testid=nodes] tr >> nth=1")
        rows = _rows(page)
        assert sorted(rows) == sorted(set(names))
        node = rows[on]
        assert node[1] == "allocated" and node[7] == f"match {match_id} (job {job}) RUNNING"
        assert node[3] == ", ".join(
            _slurm(cluster, "sinfo", "-h", "-n", on, "-o", "%f").strip().split(","))
        assert node[4].startswith("2/2") and node[6] == "1/1"
        if drained is not None:
            assert rows[drained][1].startswith("drain") and rows[drained][2].startswith(reason)
            marked = page.locator("[data-testid=nodes] tr.down td:first-child").all_inner_texts()
            assert drained in marked and all(rows[m][2] != "-" for m in marked)  # out of service
        assert page.locator("[data-testid=nodes-summary]").inner_text().startswith(
            f"{len(set(names))} node(s)")
        screenshot(page, "service-pool-slurm")
        status = json.loads(subprocess.run(
            [str(Path(sys.executable).parent / "hlvs"), "pool", "status", "--json",
             "--slurm-conf", cluster], capture_output=True, text=True, check=True).stdout)
        by_name = {n["name"]: n for n in status["nodes"]}
        assert sorted(by_name) == sorted(set(names))
        assert [(j["job_id"], j["match_id"]) for j in by_name[on]["jobs"]] == [(job, match_id)]

        _slurm(cluster, "scancel", job)
        if drained is not None:
            _slurm(cluster, "scontrol", "update", f"nodename={drained}", "state=resume")
            drained = None
        _until(lambda: _rows(page)[on][7] == "-", "the page shows the node free without reload")
    finally:
        subprocess.run(["scancel", job], env={**os.environ, "SLURM_CONF": cluster}, check=False)
        if drained is not None:
            _slurm(cluster, "scontrol", "update", f"nodename={drained}", "state=resume")
