"""An in-memory pool for unit tests of the service: matches 'run' until the test ends them.

``finish(handle, report)`` writes ``report.json`` (and a minimal ``results.json``) into the
results folder, as a real match would; ``lose(handle)`` makes the pool forget a match.
Handles survive a new :class:`FakePool` built on the same ``root`` only as files, like the
local pool's: a match is running while its ``running`` marker exists.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from service.pool import JobState, JobStatus, MatchJob


class FakePool:
    def __init__(self, *, slots: int = 1, auto_finish: bool = False) -> None:
        self.slots = slots
        self.auto_finish = auto_finish  # a running match succeeds at its first status query
        self.submitted: list[str] = []  # match ids, in order, including adopted ones
        self.started: list[str] = []  # match ids actually started
        self.cancelled: list[str] = []

    def submit(self, job: MatchJob) -> str:
        handle = str(job.work_dir)
        self.submitted.append(job.match_id)
        marker = job.work_dir / "running"
        if not marker.exists() and not (self.results_dir(handle) / "report.json").exists():
            job.work_dir.mkdir(parents=True, exist_ok=True)
            marker.write_text(job.match_id)
            self.started.append(job.match_id)
        return handle

    def status(self, handle: str) -> JobStatus:
        if self.auto_finish and (Path(handle) / "running").exists():
            self.finish(handle, {"status": "success"})
        if (Path(handle) / "running").exists():
            return JobStatus(state=JobState.RUNNING)
        if (self.results_dir(handle) / "report.json").exists():
            return JobStatus(state=JobState.FINISHED)
        return JobStatus(state=JobState.LOST, detail="forgotten by the fake pool")

    def cancel(self, handle: str) -> None:
        self.cancelled.append(handle)
        if (Path(handle) / "running").exists():
            self.finish(handle, {"status": "failed", "failure_class": "interrupted",
                                 "cause": "the orchestrator was asked to stop"})

    def results_dir(self, handle: str) -> Path:
        return Path(handle) / "out"

    # test controls -----------------------------------------------------------------------
    def finish(self, handle: str, report: dict[str, Any]) -> None:
        out = self.results_dir(handle)
        (out / "teams" / "red" / "1").mkdir(parents=True, exist_ok=True)
        (out / "teams" / "blue" / "1").mkdir(parents=True, exist_ok=True)
        (out / "public").mkdir(parents=True, exist_ok=True)
        (out / "teams" / "red" / "1" / "stdout.log").write_text("red robot log\n")
        (out / "teams" / "blue" / "1" / "stdout.log").write_text("blue robot log\n")
        (out / "public" / "referee.log").write_text("referee\n")
        (out / "results.json").write_text(json.dumps({
            "score": {"red": 1, "blue": 0},
            "robots": {"red-1": {"exit_code": 0}, "blue-1": {"exit_code": 0}}}))
        (out / "public" / "replay.hlvsrec").write_bytes(b"HLVSREC fake replay")
        (out / "report.json").write_text(json.dumps(report))
        (Path(handle) / "running").unlink(missing_ok=True)

    def lose(self, handle: str) -> None:
        (Path(handle) / "running").unlink(missing_ok=True)


__all__ = ["FakePool"]
