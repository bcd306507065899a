"""After the orchestrator is killed with SIGKILL mid-match, ``hlvs cleanup`` removes what it left:
containers, networks, host firewall rules and log mounts (found by labels and names)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
import uuid
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main as hlvs
from orchestrator.match.logfs import state_dir

pytestmark = [pytest.mark.docker, pytest.mark.root]

REPO = Path(__file__).resolve().parents[3]

SCRIPT = textwrap.dedent(
    """
    import sys
    from pathlib import Path
    from orchestrator.config import Limits
    from orchestrator.engine import connect
    from orchestrator.engine.containers import DockerRuntime
    from orchestrator.match import HostControl, MatchPlan, MatchRunner, RunOptions, TeamPlan
    from tests.integration.match.conftest import robots, spec_builder

    match_id, image, out = sys.argv[1], sys.argv[2], Path(sys.argv[3])
    red, blue = robots("red", image, [["env"]]), robots("blue", image, [["env"]])
    plan = MatchPlan(
        match_id=match_id, seed=1, red=TeamPlan(color="red", name="R", robots=tuple(red)),
        blue=TeamPlan(color="blue", name="B", robots=tuple(blue)),
        spec_builder=spec_builder(match_id, red, blue), telemetry=False,
        limits=Limits(cpus=1.0, memory_gb=0.5, log_folder_gb=0.02), grace_period_s=1.0,
    )
    options = RunOptions(out_dir=out, simulator_image=image,
                         simulator_command=("python3", "/opt/t/fakesim.py", "120"),
                         extra_labels={"org.hlvs-runner.test": "1"})
    MatchRunner(plan, runtime=DockerRuntime(connect()), host=HostControl(), options=options).run()
    """
)


def _leftovers(runtime: Any, match_id: str) -> tuple[int, bool, bool]:
    rules = subprocess.run(["iptables", "-S", "INPUT"], capture_output=True, text=True).stdout
    mounts = Path("/proc/mounts").read_text()
    return (
        len(runtime.list_project(match_id=match_id)),
        f"hlvs-runner:{match_id}" in rules,
        str(state_dir() / "logfs" / match_id) in mounts,
    )


def test_cleanup_after_kill_9(runtime: Any, test_image: str, tmp_path: Path,
                              capsys: pytest.CaptureFixture[str]) -> None:
    match_id = f"k{uuid.uuid4().hex[:8]}"
    process = subprocess.Popen(
        [sys.executable, "-c", SCRIPT, match_id, test_image, str(tmp_path / "out")],
        cwd=REPO, env={**os.environ, "PYTHONPATH": str(REPO)},
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            roles = [o.labels.get("org.hlvs-runner.role")
                     for o in runtime.list_project(match_id=match_id)]
            if roles.count("robot") == 2:
                break
            if process.poll() is not None:
                pytest.fail(f"the match process ended early: {process.communicate()[1][-2000:]}")
            time.sleep(0.2)
        else:
            pytest.fail("the robots did not start")
        time.sleep(0.5)
        os.kill(process.pid, signal.SIGKILL)
        process.wait(timeout=10)
        containers, rule, mount = _leftovers(runtime, match_id)
        assert containers == 8 and rule and mount  # simulator, 2 holders, 2 robots, 3 networks
        # (this runner has no start gate: the robots start in their holders' networks)
        capsys.readouterr()
        assert hlvs(["cleanup", "--dry-run", "--match", match_id]) == 0
        listed = json.loads(capsys.readouterr().out)
        assert listed["dry_run"] is True
        assert len(listed["containers"]) + len(listed["networks"]) == 8
        assert len(listed["networks"]) == 3 and listed["log_mounts"]
        assert all(match_id in name for name in listed["containers"] + listed["networks"])
        assert listed["salvaged"] == []  # the runner alone wrote no run record to salvage by
        assert hlvs(["cleanup", "--dry-run"]) == 0  # every match whose orchestrator is gone
        everything = json.loads(capsys.readouterr().out)
        assert not set(listed["containers"]) & set(everything["containers"])
        assert f"{match_id}: no run record (name it: hlvs cleanup --match {match_id})" in (
            everything["skipped"]
        ), "without a run record, only a cleanup naming the match removes it"
        assert _leftovers(runtime, match_id) == (containers, rule, mount)  # nothing removed
        assert hlvs(["cleanup", "--match", match_id]) == 0
        assert _leftovers(runtime, match_id) == (0, False, False)
    finally:
        if process.poll() is None:
            process.kill()
        hlvs(["cleanup", "--match", match_id])


def test_objects_whose_creation_answer_was_lost_are_still_cleaned_up(
        runtime: Any, test_image: str, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    """A runner killed while the engine creates (the request sent, the answer never read) has
    no id for the object; it entered the name first, so cleanup still removes it."""
    import requests.exceptions

    from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT
    from orchestrator.runtime.port import ContainerRequest, NetworkRequest

    match_id = f"lost{uuid.uuid4().hex[:8]}"
    labels = {LABEL_PROJECT: "1", LABEL_MATCH: match_id}
    api = runtime._client.api
    for method in ("create_container", "create_network"):
        real = getattr(api, method)

        def answer_lost(*args: Any, _real: Any = real, **kwargs: Any) -> Any:
            _real(*args, **kwargs)  # the engine makes it ...
            raise requests.exceptions.ConnectionError("the runner died before the answer")

        monkeypatch.setattr(api, method, answer_lost)
    third = int(match_id[-4:], 16) % 150 + 20  # own_engine.py takes 200-249
    try:
        with pytest.raises(Exception, match="died before the answer"):
            runtime.create_container(ContainerRequest(
                name=f"hlvs-{match_id}-robot", image=test_image, command=("sleep", "60"),
                labels=labels))
        with pytest.raises(Exception, match="died before the answer"):
            runtime.create_network(NetworkRequest(
                name=f"hlvs-{match_id}-net", subnet=f"10.251.{third}.0/24",
                gateway=f"10.251.{third}.1", internal=True, bridge_name=f"hl{match_id[-8:]}",
                labels=labels))
        monkeypatch.undo()
        found = runtime.list_project(match_id=match_id)
        assert sorted((o.kind, o.created) for o in found) == [("container", True),
                                                              ("network", True)]
        capsys.readouterr()
        assert hlvs(["cleanup", "--match", match_id]) == 0
        removed = json.loads(capsys.readouterr().out)
        assert removed["containers"] == [f"hlvs-{match_id}-robot"]
        assert removed["networks"] == [f"hlvs-{match_id}-net"]
        assert runtime.list_project(match_id=match_id) == []
        from orchestrator.runtime import ledger

        assert not ledger.intended("container", f"hlvs-{match_id}-robot")
        assert not ledger.intended("network", f"hlvs-{match_id}-net")
    finally:
        monkeypatch.undo()
        for obj in runtime.list_project(match_id=match_id):
            (runtime.remove if obj.kind == "container" else runtime.remove_network)(obj.id)


def test_a_refused_creation_leaves_no_name_behind(runtime: Any) -> None:
    """The engine answered "no" (an image it does not have): nothing was made, nothing of the
    request stays in the ledger."""
    from orchestrator.errors import OrchestratorError
    from orchestrator.runtime import ledger
    from orchestrator.runtime.port import ContainerRequest

    name = f"hlvs-refused{uuid.uuid4().hex[:8]}"
    with pytest.raises(OrchestratorError):
        runtime.create_container(ContainerRequest(
            name=name, image="hlvs-runner-test/no-such-image:none", command=("true",)))
    assert not ledger.intended("container", name)
