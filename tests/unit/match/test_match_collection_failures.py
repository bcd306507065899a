"""A robot whose logs break collection costs only its own logs: the match record is written,
everything is removed, and report.json names what was lost."""

from __future__ import annotations

import json
from pathlib import Path

from orchestrator.match import MatchRunner, RunOptions
from orchestrator.match.fake import FakeContainer, FakeHost, FakeRuntime
from orchestrator.match.logfs import LogFolder
from orchestrator.match.safecopy import CopyReport
from tests.unit.match.test_match_runner import _plan


class _BreakingHost(FakeHost):
    """Collecting red 1's folder raises what a hostile folder made the old walk raise."""

    def collect_logs(self, folder: LogFolder, destination: Path, *,
                     limit_bytes: int | None = None) -> CopyReport:
        if destination.parts[-3:-1] == ("red", "1"):
            raise RecursionError("maximum recursion depth exceeded")
        return super().collect_logs(folder, destination, limit_bytes=limit_bytes)


def test_a_robot_that_breaks_collection_loses_only_its_own_logs(tmp_path: Path) -> None:
    runtime = FakeRuntime()
    host = _BreakingHost()
    runner = MatchRunner(_plan(), runtime=runtime, host=host,
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0))
    outcome = runner.run()
    assert outcome.ok
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["status"] == "success"
    assert report["logs_cut"] == [{
        "robot": "red-1", "what": "releasing /robocup-logs of red-1",
        "reason": "RecursionError: maximum recursion depth exceeded"}]
    results = json.loads((tmp_path / "results.json").read_text())
    assert results["final_state"] == "FINISHED"
    assert (tmp_path / "teams/blue/1/stdout.log").is_file()
    assert runtime.containers == {} and runtime.networks == {}  # teardown went on
    assert host.isolated == []  # the firewall rules went too


def test_console_output_over_the_cap_is_cut_and_named(tmp_path: Path) -> None:
    from orchestrator.match.layout import ROBOT_CONSOLE_BYTES

    runtime = FakeRuntime()

    def flood(container: FakeContainer) -> None:
        if container.request.name.endswith("-blue-2"):
            container.console["stdout"] = "x" * ROBOT_CONSOLE_BYTES

    runtime.on_start = flood
    runner = MatchRunner(_plan(), runtime=runtime, host=FakeHost(),
                         options=RunOptions(out_dir=tmp_path, simulator_image="sim:1",
                                            poll_s=0.0))
    assert runner.run().ok
    stdout = tmp_path / "teams/blue/2/stdout.log"
    assert stdout.stat().st_size == ROBOT_CONSOLE_BYTES // 2
    report = json.loads((tmp_path / "report.json").read_text())
    assert report["logs_cut"] == [{"robot": "blue-2", "what": "stdout.log",
                                   "reason": f"cut at the limit of {ROBOT_CONSOLE_BYTES // 2} "
                                             "bytes"}]
