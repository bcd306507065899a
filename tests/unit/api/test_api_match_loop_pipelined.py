"""Pipelined lockstep: the answer to the measurement of step N is applied at step N+2."""

from __future__ import annotations

from contracts.ids import RobotId, TeamColor
from simulator.api import LockstepSettings
from simulator.api.connection import AnswerBook
from simulator.match_loop import LoopSettings, MatchLoop
from simulator.telemetry import NullTelemetry
from tests.unit.api.test_api_match_loop_pacing import _Referee, _World

ROBOT = RobotId(TeamColor.RED, 1)


class _PipelineServer:
    """Records the order of the loop's calls; a client answers every sent measurement."""

    stop_requested = False
    connection_changes = 0
    awaiting_answers = False
    exchanging = False  # no exchange thread (simulator.api.exchange)

    def settle_exchange(self, wait_s: float) -> bool:
        return False

    def __init__(self, world: _World) -> None:
        self.world = world
        self.slots: dict[RobotId, object] = {}  # wait_lockstep: nobody to wait for
        self.answers = AnswerBook()
        self.sent: list[int] = []
        self.calls: list[str] = []
        self.applied: list[tuple[int, list[str]]] = []

    def poll(self, timeout_s: float = 0.0) -> None:
        return None

    def take_requests(self) -> dict[RobotId, list[str]]:
        self.calls.append("take")
        return {ROBOT: [f"answer {self.sent[-1]}"]} if self.sent else {}

    def publish(self, time_ms: int) -> None:
        self.publish_prepared(self.prepare(time_ms))

    def prepare(self, time_ms: int) -> int:
        assert time_ms == self.world.sim_time_ms
        return time_ms

    def publish_prepared(self, time_ms: int) -> None:
        self.calls.append("publish")
        self.sent.append(time_ms)

    def apply_taken(self, taken: dict[RobotId, list[str]], step_time_ms: int) -> None:
        self.calls.append("apply")
        self.applied.append((step_time_ms, taken.get(ROBOT, [])))

    def apply_requests(self, step_time_ms: int) -> None:
        """Take and apply in one pass (the pipeline's usual step)."""
        self.calls.append("take+apply")
        self.applied.append((step_time_ms, [f"answer {self.sent[-1]}"] if self.sent else []))

    def connected(self) -> list[str]:
        return []


def test_answers_apply_one_step_later_than_in_lockstep() -> None:
    world = _World()
    server = _PipelineServer(world)
    loop = MatchLoop(
        world=world,
        referee=_Referee(world, end_ms=80),
        server=server,  # type: ignore[arg-type]
        recorder=None,
        telemetry=NullTelemetry(),
        settings=LoopSettings(
            stepping="pipelined",
            maximum_real_time_factor=0.0,
            lockstep=LockstepSettings(deadline_s=0.05, time_bank_s=1.0),
            end_of_game_real_s=0.0,
            max_duration_real_s=10.0,
        ),
    )
    assert loop.run() == "finished" and world.sim_time_ms == 80
    # the measurement of each step goes out after the answers to the previous one are taken
    # (and applied: nothing can have answered it yet)
    assert server.calls[:5] == ["apply", "take+apply", "publish", "take+apply", "publish"]
    assert server.sent == list(range(8, 81, 8))  # the last one before the end-of-game hold
    for step_time_ms, answers in server.applied[2:]:
        assert answers == [f"answer {step_time_ms - 16}"]  # measurement N -> step N+2
    assert server.applied[0] == (8, []) and server.applied[1] == (16, [])
