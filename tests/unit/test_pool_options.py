"""--pool plumbing without a cluster: the schedule's pool section, and the exit code of a match
played elsewhere read back from the files it left."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from contracts.match_results import Forfeit, MatchLimits, MatchReport, MatchResults
from hlvs.commands.outcome import summarize
from hlvs.commands.pooled import read_outcome
from orchestrator.config.schedule import load_schedule
from orchestrator.errors import ConfigError


def _schedule(tmp: Path, pool: str) -> Path:
    (tmp / "a.json").write_text(json.dumps({"name": "a", "players": {}}))
    (tmp / "b.json").write_text(json.dumps({"name": "b", "players": {}}))
    path = tmp / "s.yaml"
    path.write_text("name: cup\nteams:\n  - {name: a, id: 1, config: a.json}\n"
                    f"  - {{name: b, id: 2, config: b.json}}\n{pool}")
    return path


def test_schedule_pool_section(tmp_path: Path) -> None:
    assert load_schedule(_schedule(tmp_path, "")).pool.kind == "local"
    pool = load_schedule(_schedule(
        tmp_path, "pool: {kind: slurm, slurm_conf: /etc/slurm/slurm.conf, account: league}\n"
    )).pool
    assert (pool.kind, pool.slurm_conf, pool.account) == ("slurm", "/etc/slurm/slurm.conf",
                                                         "league")
    with pytest.raises(ConfigError) as err:
        load_schedule(_schedule(tmp_path, "pool: {kind: k8s}\n"))
    assert "/pool/kind" in str(err.value)
    with pytest.raises(ConfigError) as err:
        load_schedule(_schedule(tmp_path, "pool: {kind: slurm, partiton: x}\n"))
    assert "/pool/partiton" in str(err.value) and "unknown key" in str(err.value)


LIMITS = MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                     team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                     allow_internet=False, host_controls=None)
FORFEIT = Forfeit(team="red", winner="blue", reason="no usable image",
                  score={"red": 0, "blue": 0})


@pytest.mark.parametrize(("report", "results", "code"), [
    ({"status": "success"}, {"score": {"red": 1, "blue": 0}, "winner": "red"}, 0),
    ({"status": "success"}, {"forfeit": FORFEIT, "winner": "blue"}, 4),
    ({"status": "failed", "failure_class": "interrupted", "cause": "SIGTERM"}, {}, 130),
    ({"status": "failed", "failure_class": "infrastructure", "cause": "engine"}, {}, 3),
    ({"status": "failed", "failure_class": "simulator", "cause": "exited"}, {}, 1),
])
def test_exit_code_of_a_match_played_in_the_pool(
    tmp_path: Path, report: dict[str, str], results: dict[str, Any], code: int,
    capsys: pytest.CaptureFixture[str],
) -> None:
    (tmp_path / "report.json").write_text(json.dumps(report))
    failure = MatchReport.from_dict(report).failure
    MatchResults(match_id="m1", seed=1, status="success" if failure is None else "failed",
                 failure=failure, limits=LIMITS, **results).write(tmp_path / "results.json")
    assert summarize(read_outcome("m1", tmp_path), as_json=True) == code
    assert json.loads(capsys.readouterr().out)["exit_code"] == code


def test_slurm_submission_requeues_test_matches_only(tmp_path: Path) -> None:
    from cluster import MatchJob
    from cluster.slurm import SlurmPool

    calls: list[tuple[list[str], str | None]] = []

    class Recording(SlurmPool):  # Slurm's commands recorded at the adapter's one boundary
        def _run(self, args: list[str], *, handle: str, stdin: str | None = None,
                 ok_codes: tuple[int, ...] = (0,)) -> str:
            calls.append((args, stdin))
            return "42\n" if args[0] == "sbatch" else ""

    pool = Recording(out_subdir="")
    game = tmp_path / "game.json"
    for requeue, flag in ((True, "--requeue"), (False, "--no-requeue")):
        work = tmp_path / flag
        handle = pool.submit(MatchJob(match_id="m", game_path=game, work_dir=work,
                                      requeue=requeue, match_args=("--grace", "3")))
        args, script = calls[-1]
        assert flag in args and "--exclusive" in args
        assert script is not None and f"--out {work}" in script and "--grace 3" in script
        assert pool.results_dir(handle) == work and pool.job_id(handle) == "42"
        assert pool.recorded(work) == handle
        assert "cleanup --match m" in script  # a requeued run salvages the dead one first


def test_node_failure_of_an_official_match_is_an_infrastructure_failure(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
) -> None:
    import argparse

    from cluster import JobState, JobStatus
    from hlvs.commands import pooled
    from orchestrator.errors import InfrastructureError

    class Ended:  # the pool's port as the command sees it, after a node failure
        def recorded(self, work: Path) -> str | None:
            return None

        def submit(self, job: object) -> str:
            return f"slurm:7:{tmp_path}"

        def job_id(self, handle: str) -> str:
            return "7"

        def status(self, handle: str) -> JobStatus:
            return JobStatus(state=JobState.LOST, detail="Slurm job 7 ended (NODE_FAIL|0:0)")

        def final_state(self, handle: str) -> str:
            return "NODE_FAIL"

    monkeypatch.setattr(pooled, "make_pool", lambda args: Ended())
    with pytest.raises(InfrastructureError) as err:
        pooled.play_in_pool(argparse.Namespace(json=True), game_path=tmp_path / "g.json",
                            match_id="m1", out_dir=tmp_path, official=True)
    assert "NODE_FAIL" in str(err.value) and "hlvs cleanup --match m1" in str(err.value)
    assert err.value.exit_code == 3
