"""The stepping policies, each alone over a server that records what it is asked: which
requests a step applies, when its measurement goes out, what a hold and the end do."""

from __future__ import annotations

import pytest

from contracts.ids import RobotId, TeamColor
from simulator.api import (
    AsyncStepping,
    LockstepSettings,
    LockstepStepping,
    PipelinedStepping,
    stepping_for,
)
from simulator.api.connection import AnswerBook
from simulator.api.stepping import hold_text

ROBOT = RobotId(TeamColor.RED, 1)
SETTINGS = LockstepSettings(deadline_s=60.0, time_bank_s=1.0)  # nobody is ever late here


class _Server:
    """A client that answers each measurement at once; every call is recorded."""

    stop_requested = False
    awaiting_answers = False
    exchanging = False  # no exchange thread (simulator.api.exchange)

    def settle_exchange(self, wait_s: float) -> bool:
        return False

    def __init__(self) -> None:
        self.answers = AnswerBook()  # nobody owes an answer: the lockstep wait returns at once
        self.slots: dict[RobotId, object] = {}
        self.sent: list[int] = []
        self.calls: list[tuple[str, int]] = []
        self.applied: list[tuple[int, list[str]]] = []

    def poll(self, timeout_s: float = 0.0) -> None:
        raise AssertionError("nobody owes an answer: the wait does not poll")

    def _answers(self) -> list[str]:
        return [f"answer {self.sent[-1]}"] if self.sent else []

    def apply_requests(self, step_time_ms: int) -> None:
        self.calls.append(("take+apply", step_time_ms))
        self.applied.append((step_time_ms, self._answers()))

    def take_requests(self) -> dict[RobotId, list[str]]:
        self.calls.append(("take", -1))
        answers = self._answers()
        return {ROBOT: answers} if answers else {}

    def apply_taken(self, taken: dict[RobotId, list[str]], step_time_ms: int) -> None:
        self.calls.append(("apply", step_time_ms))
        self.applied.append((step_time_ms, taken.get(ROBOT, [])))

    def prepare(self, time_ms: int) -> int:
        return time_ms

    def publish_prepared(self, time_ms: int) -> None:
        self.calls.append(("publish", time_ms))
        self.sent.append(time_ms)

    def publish(self, time_ms: int) -> None:
        self.publish_prepared(self.prepare(time_ms))

    def hold_notice(self, time_ms: int, text: str) -> int:
        self.calls.append(("notice", time_ms))
        assert text == hold_text(time_ms)
        return 1


def _steps(stepping: object, count: int, start_ms: int = 0) -> int:
    """``count`` steps of 8 ms as the match loop takes them; returns the time reached."""
    time_ms = start_ms
    for _ in range(count):
        stepping.before_step(time_ms, time_ms + 8)  # type: ignore[attr-defined]
        time_ms += 8  # the world steps, the referee judges
        stepping.after_step(time_ms)  # type: ignore[attr-defined]
    return time_ms


def test_async_applies_what_arrived_then_sends_and_never_holds() -> None:
    server = _Server()
    stepping = AsyncStepping(server)  # type: ignore[arg-type]
    assert not stepping.holds
    time_ms = _steps(stepping, 3)
    assert server.calls == [("take+apply", 8), ("publish", 8), ("take+apply", 16),
                            ("publish", 16), ("take+apply", 24), ("publish", 24)]  # fmt: skip
    assert server.applied == [(8, []), (16, ["answer 8"]), (24, ["answer 16"])]
    before = list(server.calls)
    stepping.hold(time_ms, finished=False)
    stepping.end(time_ms)
    assert server.calls == before and stepping.waited_s == 0.0


def test_lockstep_waits_then_applies_the_answers_to_the_last_step() -> None:
    server = _Server()
    stepping = LockstepStepping(server, SETTINGS)  # type: ignore[arg-type]
    assert stepping.holds
    _steps(stepping, 3)
    # measurement N is answered and applied at step N+1
    assert server.applied == [(8, []), (16, ["answer 8"]), (24, ["answer 16"])]
    assert server.sent == [8, 16, 24]
    assert stepping.waited_s == 0.0  # every answer was in before each wait


def test_lockstep_tells_why_it_holds_until_the_game_is_over() -> None:
    server = _Server()
    stepping = LockstepStepping(server, SETTINGS)  # type: ignore[arg-type]
    stepping.hold(0, finished=False)
    assert server.calls == [("notice", 0)]
    stepping.hold(0, finished=True)  # the game is over: no notice, nothing sent
    stepping.end(0)
    assert server.calls == [("notice", 0)]


def test_pipelined_applies_the_answers_one_step_later_than_lockstep() -> None:
    server = _Server()
    stepping = PipelinedStepping(server, SETTINGS)  # type: ignore[arg-type]
    assert stepping.holds
    time_ms = _steps(stepping, 5)
    # the first step applies nothing taken; then each step sends the previous step's
    # measurement before applying the answers to the one sent before it
    assert server.calls[:5] == [("apply", 8), ("take+apply", 16), ("publish", 8),
                                ("take+apply", 24), ("publish", 16)]  # fmt: skip
    assert server.sent == [8, 16, 24, 32]  # the last step's measurement is not sent yet
    for step_time_ms, answers in server.applied[2:]:
        assert answers == [f"answer {step_time_ms - 16}"]  # measurement N -> step N+2
    assert stepping.unsent
    stepping.end(time_ms)
    assert server.calls[-1] == ("publish", time_ms) == ("publish", 40)


def test_pipelined_sends_the_held_step_once_and_keeps_its_answers_for_the_next_step() -> None:
    server = _Server()
    stepping = PipelinedStepping(server, SETTINGS)  # type: ignore[arg-type]
    time_ms = _steps(stepping, 2)
    stepping.hold(time_ms, finished=False)
    stepping.hold(time_ms, finished=False)  # once sent, a hold sends nothing more
    assert server.sent == [8, 16] and server.calls[-2:] == [("take", -1), ("publish", 16)]
    stepping.end(time_ms)  # nothing unsent
    assert server.sent == [8, 16]
    _steps(stepping, 1, time_ms)  # the answers taken during the hold apply at the next step
    assert server.calls[-1] == ("apply", 24) and server.applied[-1] == (24, ["answer 8"])


def test_stepping_for_names_each_policy() -> None:
    server = _Server()
    assert isinstance(stepping_for("async", server, SETTINGS), AsyncStepping)  # type: ignore[arg-type]
    assert isinstance(stepping_for("lockstep", server, SETTINGS), LockstepStepping)  # type: ignore[arg-type]
    assert isinstance(stepping_for("pipelined", server, SETTINGS), PipelinedStepping)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="async, lockstep, pipelined"):
        stepping_for("free", server, SETTINGS)  # type: ignore[arg-type]


def test_lockstep_prefetches_the_next_step_as_its_wait_begins() -> None:
    """Lockstep begins the next step's position stage before its wait and the answers taken;
    pipelined (whose wait is short) is given none."""
    server = _Server()
    marks: list[int] = []
    stepping = stepping_for("lockstep", server, SETTINGS,  # type: ignore[arg-type]
                            prefetch=lambda: marks.append(len(server.calls)))
    time_ms = _steps(stepping, 3)
    stepping.hold(time_ms, finished=False)  # a hold computes nothing ahead
    assert marks == [0, 2, 4] and server.calls[0] == ("take+apply", 8)
    pipelined = stepping_for("pipelined", _Server(), SETTINGS,  # type: ignore[arg-type]
                             prefetch=lambda: marks.append(-1))
    _steps(pipelined, 3)
    assert -1 not in marks
