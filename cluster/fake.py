"""An in-memory pool for unit tests of the service: matches 'run' until the test ends them.

``finish(handle, report)`` writes ``report.json`` (and a ``results.json`` to match) into the
results folder, as a real match would; ``lose(handle)`` makes the pool forget a match.
Handles survive a new :class:`FakePool` built on the same ``root`` only as files, like the
local pool's: a match is running while its ``running`` marker exists.
"""

from __future__ import annotations

from pathlib import Path

from cluster import JobState, JobStatus, MatchJob, NodeJob, PoolNode
from contracts import (
    Failure,
    JSONObject,
    MatchLimits,
    MatchReport,
    MatchResults,
    PlayRecord,
    RobotResult,
    files,
)
from orchestrator import private_dir, write_private


class FakePool:
    def __init__(self, *, slots: int = 1, auto_finish: bool = False) -> None:
        self.slots = slots
        self.auto_finish = auto_finish  # a running match succeeds at its first status query
        self.submitted: list[str] = []  # match ids, in order, including adopted ones
        self.started: list[str] = []  # match ids actually started
        self.cancelled: list[str] = []
        self.handles: dict[str, str] = {}  # handle -> match id

    def submit(self, job: MatchJob) -> str:
        handle = str(job.work_dir)
        self.submitted.append(job.match_id)
        self.handles[handle] = job.match_id
        marker = job.work_dir / "running"
        if not marker.exists() and not (self.results_dir(handle) / files.REPORT).exists():
            private_dir(job.work_dir)
            write_private(marker, job.match_id)
            self.started.append(job.match_id)
        return handle

    def status(self, handle: str) -> JobStatus:
        if self.auto_finish and (Path(handle) / "running").exists():
            self.finish(handle, {"status": "success"})
        if (Path(handle) / "running").exists():
            return JobStatus(state=JobState.RUNNING)
        if (self.results_dir(handle) / files.REPORT).exists():
            return JobStatus(state=JobState.FINISHED)
        return JobStatus(state=JobState.LOST, detail="forgotten by the fake pool")

    def cancel(self, handle: str) -> None:
        self.cancelled.append(handle)
        if (Path(handle) / "running").exists():
            # stopped after kick-off: the simulator writes the play up to the stop
            self.finish(handle, {"status": "failed", "failure_class": "interrupted",
                                 "cause": "the orchestrator was asked to stop"}, played=True)

    def results_dir(self, handle: str) -> Path:
        return Path(handle) / "out"

    def nodes(self) -> list[PoolNode]:
        """One node, ``fake-node``, with the matches running on it."""
        jobs = tuple(NodeJob(job_id=f"fake-{i}", match_id=match_id, state="running")
                     for i, (handle, match_id) in enumerate(self.handles.items())
                     if (Path(handle) / "running").exists())
        return [PoolNode(name="fake-node", state="up", reason="", features=("fake",), cpus=2,
                         cpus_allocated=None, cpu_load=None, memory_mb=1024, memory_free_mb=512,
                         slots=self.slots, jobs=jobs)]

    # test controls -----------------------------------------------------------------------
    def finish(self, handle: str, report: JSONObject, *, played: bool | None = None) -> None:
        """End the match with ``report`` as its report.json (checked as a MatchReport);
        ``played``: results.json has the play of both halves (default: when it did not
        fail)."""
        out = self.results_dir(handle)
        (out / "teams" / "red" / "1").mkdir(parents=True, exist_ok=True)
        (out / "teams" / "blue" / "1").mkdir(parents=True, exist_ok=True)
        (out / "public").mkdir(parents=True, exist_ok=True)
        (out / "teams" / "red" / "1" / "stdout.log").write_text("red robot log\n")
        (out / "teams" / "blue" / "1" / "stdout.log").write_text("blue robot log\n")
        (out / "public" / "referee.log").write_text("referee\n")
        match_report = MatchReport.from_dict(report, source="FakePool.finish(report=...)")
        failure = match_report.failure
        fake_results(Path(handle).name, failure, played=played).write(out / files.RESULTS)
        (out / "public" / files.REPLAY).write_bytes(b"HLVSREC fake replay")
        match_report.write(out / files.REPORT)
        (Path(handle) / "running").unlink(missing_ok=True)

    def lose(self, handle: str) -> None:
        (Path(handle) / "running").unlink(missing_ok=True)


def fake_results(match_id: str, failure: Failure | None, *,
                 played: bool | None = None) -> MatchResults:
    """A played 1-0 with one robot a side that both exited 0 (failed: ``failure``): both
    halves reached PLAYING, red kicked its goal in (``play`` left out of a failed match unless
    ``played``)."""
    zero = {"red": 0, "blue": 0}
    play = PlayRecord(halves_playing=(1, 2), both_halves_playing=True, playing_s=80.0,
                      kicks={"red": 1, "blue": 0}, shots={"red": 1, "blue": 0},
                      goals={"red": 1, "blue": 0}, own_goals=zero, falls=zero)
    robots = {key: RobotResult(image="team/image:1", container=f"{match_id}-{key}", exit_code=0)
              for key in ("red-1", "blue-1")}
    return MatchResults(
        match_id=match_id, seed=1, status="failed" if failure else "success", failure=failure,
        final_state="FINISHED", score={"red": 1, "blue": 0}, winner="red", robots=robots,
        play=play if (failure is None if played is None else played) else None,
        limits=MatchLimits(cpus=4.0, memory_gb=16.0, pids=1024, log_folder_gb=10.0,
                           team_api_mb_s=350.0, team_comm_mb_s=1.0, grace_period_s=5.0,
                           allow_internet=False, host_controls=None),
    )  # fmt: skip


__all__ = ["FakePool"]
