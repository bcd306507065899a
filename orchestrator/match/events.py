"""The progress of one match as a stream of typed events.

A match (:class:`orchestrator.match.runner.MatchRunner` and its phases, through
:attr:`orchestrator.match.deps.MatchDeps.events`) publishes each step as it happens; an
observer (the service's pre-flight, a console) subscribes before the match runs and reads its
own queue, instead of polling the match's fields from another thread.
"""

from __future__ import annotations

import queue
import threading
from dataclasses import dataclass

from orchestrator.match.results import Failure
from orchestrator.match.state import MatchState


@dataclass(frozen=True, slots=True, kw_only=True)
class StateChanged:
    """The match entered ``state`` (the lifecycle's transition)."""

    state: MatchState


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotNotStarted:
    """A robot's container could not be created or started."""

    key: str
    color: str
    image: str | None
    cause: str


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotExited:
    """A robot's container exited while the match ran (the game goes on)."""

    key: str
    color: str
    image: str | None
    exit_code: int | None
    oom_killed: bool


@dataclass(frozen=True, slots=True, kw_only=True)
class AllConnected:
    """Every started robot is connected to the simulator's robot API."""

    bringup_s: float


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchFailed:
    """The match's failure (the first one; the match still stops and collects)."""

    failure: Failure


@dataclass(frozen=True, slots=True, kw_only=True)
class MatchEnded:
    """The runner returned: the match is stopped and collected (last event of a match)."""

    failure: Failure | None


MatchEvent = StateChanged | RobotNotStarted | RobotExited | AllConnected | MatchFailed | MatchEnded


class EventStream:
    """Publishes a match's events to every subscriber's queue (thread-safe)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._subscribers: list[queue.SimpleQueue[MatchEvent]] = []

    def subscribe(self) -> queue.SimpleQueue[MatchEvent]:
        """A queue that gets every event published from now on."""
        subscriber: queue.SimpleQueue[MatchEvent] = queue.SimpleQueue()
        with self._lock:
            self._subscribers.append(subscriber)
        return subscriber

    def publish(self, event: MatchEvent) -> None:
        with self._lock:
            subscribers = list(self._subscribers)
        for subscriber in subscribers:
            subscriber.put(event)


__all__ = ["AllConnected", "EventStream", "MatchEnded", "MatchEvent", "MatchFailed",
           "RobotExited", "RobotNotStarted", "StateChanged"]
