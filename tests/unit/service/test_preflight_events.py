"""The pre-flight follows its match's events: the answer names the robot and the cause."""

from __future__ import annotations

import queue
from typing import Any

from orchestrator.match import (
    AllConnected,
    Failure,
    FailureClass,
    MatchEnded,
    RobotExited,
    RobotNotStarted,
    StateChanged,
)
from orchestrator.match.state import MatchState
from service.preflight import _connected_or_failure


def _follow(*events: Any, timeout_s: float = 5.0) -> Any:
    stream: queue.SimpleQueue[Any] = queue.SimpleQueue()
    for event in events:
        stream.put(event)
    return _connected_or_failure(stream, timeout_s=timeout_s, images=["team/robot:1"])


def test_connected_robots_pass() -> None:
    assert _follow(StateChanged(state=MatchState.WAITING), AllConnected(bringup_s=2.0)) is None


def test_a_team_robot_that_exits_fails_the_start_stage() -> None:
    failure = _follow(RobotExited(key="blue-1", color="blue", image="stub:1", exit_code=1,
                                  oom_killed=False),
                      RobotExited(key="red-1", color="red", image="team/robot:1",
                                  exit_code=137, oom_killed=True))
    assert failure is not None and failure.fields()["stage"] == "start"
    assert failure.fields()["image"] == "team/robot:1"
    assert "exited with code 137 (out of memory)" in str(failure)


def test_a_robot_that_did_not_start_is_named_with_its_cause() -> None:
    failure = _follow(RobotNotStarted(key="red-1", color="red", image="team/robot:1",
                                      cause="exec: start: executable file not found"))
    assert failure is not None and "executable file not found" in str(failure)


def test_a_match_that_ends_early_fails_with_its_cause() -> None:
    ended = MatchEnded(failure=Failure(failure_class=FailureClass.SIMULATOR, cause="crashed"))
    failure = _follow(StateChanged(state=MatchState.STARTING), ended)
    assert failure is not None and failure.fields()["image"] == "(simulator)"
    assert "crashed" in str(failure)


def test_no_connection_before_the_deadline_is_the_connect_stage() -> None:
    failure = _follow(StateChanged(state=MatchState.WAITING), timeout_s=0.05)
    assert failure is not None and failure.fields()["stage"] == "connect"
    assert failure.fields()["image"] == "team/robot:1"
