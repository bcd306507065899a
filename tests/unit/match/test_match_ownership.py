"""Matches own what they create: a running match id is refused, cleanup touches only matches
whose orchestrator is gone and salvages their logs first (fake engine, real files)."""

from __future__ import annotations

import json
import os
import socket
import stat
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from contracts import process
from orchestrator.match import ownership
from orchestrator.match.cleanup import cleanup, plan_cleanup
from orchestrator.match.fake import FakeHost, FakeRuntime
from orchestrator.match.layout import labels
from orchestrator.match.ownership import LABEL_RUN, MatchRunning, RunRecord
from orchestrator.runtime.port import ContainerRequest


@pytest.fixture(autouse=True)
def state(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Path:
    monkeypatch.setenv("HLVS_STATE_DIR", str(tmp_path / "state"))
    return tmp_path / "state"


def _dead_record(match_id: str, out: Path) -> RunRecord:
    record = RunRecord(match_id=match_id, run_id=f"run-{match_id}", pid=os.getpid(),
                       pid_start="0", hostname=socket.gethostname(), out_dir=str(out),
                       started_unix_s=0.0, pid_namespace=process.pid_namespace(),
                       )  # pid_start 0: this pid is some other process now
    ownership.runs_dir().mkdir(parents=True, exist_ok=True)
    ownership.record_path(match_id).write_text(json.dumps(asdict(record)))
    return record


def _robot(runtime: FakeRuntime, match_id: str, run: str, team: str, number: int) -> str:
    cid = runtime.create_container(ContainerRequest(
        name=f"hlvs-{match_id}-{team}-{number}", image="img",
        labels={**labels(match_id, "robot", team=team, robot=str(number)), LABEL_RUN: run}))
    runtime.start(cid)
    return cid


def test_second_claim_of_a_running_match_is_refused_with_its_details(tmp_path: Path) -> None:
    with ownership.claim("m1", tmp_path / "out") as first:
        with pytest.raises(MatchRunning) as refused:
            with ownership.claim("m1", tmp_path / "other"):
                pass
        assert refused.value.record == first.record
        message = str(refused.value)
        assert f"pid {os.getpid()}" in message and str(tmp_path / "out") in message
    with ownership.claim("m1", tmp_path / "again") as second:  # released at the end
        assert second.previous is None


def test_claim_after_a_dead_orchestrator_hands_back_its_record(tmp_path: Path) -> None:
    dead = _dead_record("m2", tmp_path / "out")
    with ownership.claim("m2", tmp_path / "out") as claim:
        assert claim.previous == dead
        assert ownership.read("m2") == claim.record


def test_cleanup_touches_only_dead_matches_and_salvages_their_logs(tmp_path: Path) -> None:
    runtime, host = FakeRuntime(), FakeHost()
    out = tmp_path / "dead-out"
    _dead_record("dead", out)
    dead_robot = _robot(runtime, "dead", "run-dead", "red", 1)
    with ownership.claim("alive", tmp_path / "alive-out") as alive:
        _robot(runtime, "alive", alive.record.run_id, "blue", 2)
        _robot(runtime, "unowned", "x", "red", 1)
        planned = plan_cleanup(runtime, match_id=None)  # a dry run: the same decisions
        assert planned.containers == ("hlvs-dead-red-1",) and planned.salvaged == (str(out),)
        assert any(s.startswith("alive: its orchestrator") for s in planned.skipped)
        assert any(s.startswith("unowned: no run record") for s in planned.skipped)
        assert len(runtime.list_project()) == 3 and not out.exists()  # nothing done
        assert ownership.read("dead") is not None
        with pytest.raises(MatchRunning):
            plan_cleanup(runtime, match_id="alive")
        report = cleanup(runtime, host, match_id=None)
        assert report.containers == ("hlvs-dead-red-1",)
        assert report.salvaged == (str(out),)
        assert any(s.startswith("alive: its orchestrator") for s in report.skipped)
        assert any(s.startswith("unowned: no run record") for s in report.skipped)
        assert ("stop", dead_robot) in runtime.calls
        assert (out / "teams/red/1/stdout.log").is_file()
        assert json.loads((out / "report.json").read_text())["failure_class"] == "interrupted"
        assert json.loads((out / "results.json").read_text())["status"] == "failed"
        assert ownership.read("dead") is None
        with pytest.raises(MatchRunning):
            cleanup(runtime, host, match_id="alive")
    remaining = {o.name for o in runtime.list_project()}
    assert remaining == {"hlvs-alive-blue-2", "hlvs-unowned-red-1"}
    named = cleanup(runtime, host, match_id="unowned")  # named: removed without a record
    assert named.containers == ("hlvs-unowned-red-1",) and named.salvaged == ()


def test_a_record_from_another_host_counts_as_alive(tmp_path: Path) -> None:
    record = replace(_dead_record("far", tmp_path), hostname="elsewhere")
    assert ownership.owner_alive(record)


def test_a_record_from_another_pid_namespace_counts_as_alive(tmp_path: Path) -> None:
    """An orchestrator in a container (or a cluster job) sharing the state folder: its pid means
    nothing here, so cleanup leaves its match alone rather than remove a running match."""
    dead = _dead_record("boxed", tmp_path)
    assert not ownership.owner_alive(dead)  # this namespace: judged by pid and start time
    assert ownership.owner_alive(replace(dead, pid_namespace="4026530000"))
    with ownership.claim("mine", tmp_path / "out") as mine:
        assert mine.record.pid_namespace == process.pid_namespace() != ""
        written = json.loads(ownership.record_path("mine").read_text())
        assert written["pid_namespace"] == process.pid_namespace()


def test_a_record_of_an_earlier_version_is_judged_by_pid_and_start_time(tmp_path: Path) -> None:
    data = asdict(_dead_record("old", tmp_path))
    del data["pid_namespace"]
    old = RunRecord.from_json(data)
    assert old is not None and old.pid_namespace == ""
    assert not ownership.owner_alive(old)
    assert ownership.owner_alive(replace(old, pid_start=str(process.start_time(os.getpid()))))


def test_cleanup_leaves_a_container_that_only_carries_our_labels(tmp_path: Path) -> None:
    """An image with our labels baked in, started outside the runner: named or not, cleanup
    does not remove it (it is not in the runner's records), and says why."""
    runtime, host = FakeRuntime(), FakeHost()
    _dead_record("victim", tmp_path / "out")
    ours = _robot(runtime, "victim", "run-victim", "red", 1)
    foreign = _robot(runtime, "victim", "run-victim", "blue", 1)
    runtime.foreign.add(foreign)
    planned = plan_cleanup(runtime, match_id="victim")
    assert planned.containers == ("hlvs-victim-red-1",)
    report = cleanup(runtime, host, match_id="victim")
    assert report.containers == ("hlvs-victim-red-1",)
    assert any("hlvs-victim-blue-1" in s and "did not create it" in s for s in report.skipped)
    assert ours not in runtime.containers and foreign in runtime.containers


def test_ledger_records_ids_and_forgets_them(state: Path) -> None:
    from orchestrator.runtime import ledger

    cid = "ab" * 32
    assert not ledger.created(cid)
    ledger.note(cid)
    assert ledger.created(cid)
    assert stat.S_IMODE(ledger.ledger_dir().stat().st_mode) == 0o700
    ledger.note("../../etc/passwd")  # not an engine id: never a path
    assert not ledger.created("../../etc/passwd")
    assert sorted(p.name for p in ledger.ledger_dir().iterdir()) == [cid]
    ledger.forget(cid)
    assert not ledger.created(cid)
