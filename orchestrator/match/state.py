"""The match lifecycle as an explicit state machine.

PENDING -> PULLING -> STARTING -> WAITING -> PLAYING -> STOPPING -> COLLECTING -> DONE, and FAILED
from any state before DONE. STOPPING may also follow STARTING or WAITING (a failure or an
interrupt before play) and PULLING (a forfeit). COLLECTING may end in FAILED (the failure
recorded while playing). Every transition is logged with the match id and the time spent in the
previous state.
"""

from __future__ import annotations

import enum
import logging
import time
from collections.abc import Callable

from orchestrator.errors import OrchestratorError

log = logging.getLogger(__name__)


class MatchState(enum.Enum):
    PENDING = "pending"
    PULLING = "pulling"
    STARTING = "starting"
    WAITING = "waiting"
    PLAYING = "playing"
    STOPPING = "stopping"
    COLLECTING = "collecting"
    DONE = "done"
    FAILED = "failed"


_S = MatchState
ALLOWED: dict[MatchState, frozenset[MatchState]] = {
    _S.PENDING: frozenset({_S.PULLING, _S.FAILED}),
    _S.PULLING: frozenset({_S.STARTING, _S.STOPPING, _S.FAILED}),
    _S.STARTING: frozenset({_S.WAITING, _S.STOPPING, _S.FAILED}),
    _S.WAITING: frozenset({_S.PLAYING, _S.STOPPING, _S.FAILED}),
    _S.PLAYING: frozenset({_S.STOPPING, _S.FAILED}),
    _S.STOPPING: frozenset({_S.COLLECTING, _S.FAILED}),
    _S.COLLECTING: frozenset({_S.DONE, _S.FAILED}),
    _S.DONE: frozenset(),
    _S.FAILED: frozenset(),
}


class IllegalMatchTransition(OrchestratorError):
    def __init__(self, *, match_id: str, source: MatchState, target: MatchState) -> None:
        self.match_id = match_id
        self.source = source
        self.target = target
        allowed = ", ".join(sorted(s.name for s in ALLOWED[source])) or "none"
        super().__init__(
            f"match {match_id}: illegal transition {source.name} -> {target.name} "
            f"(allowed from {source.name}: {allowed})"
        )


class Lifecycle:
    """Holds the current state and the seconds spent in each state (``timings_s``)."""

    def __init__(self, match_id: str, *, clock: Callable[[], float] = time.monotonic) -> None:
        self.match_id = match_id
        self._clock = clock
        self._state = MatchState.PENDING
        self._entered = clock()
        self.timings_s: dict[str, float] = {}
        self.history: list[MatchState] = [MatchState.PENDING]
        self.observers: list[Callable[[MatchState], None]] = []

    @property
    def state(self) -> MatchState:
        return self._state

    def advance(self, target: MatchState) -> None:
        if target not in ALLOWED[self._state]:
            raise IllegalMatchTransition(match_id=self.match_id, source=self._state, target=target)
        now = self._clock()
        spent = now - self._entered
        key = self._state.value
        self.timings_s[key] = round(self.timings_s.get(key, 0.0) + spent, 3)
        log.info(
            "match %s: %s -> %s (%.2f s in %s)",
            self.match_id, self._state.name, target.name, spent, self._state.name,
        )
        self._state = target
        self._entered = now
        self.history.append(target)
        for observer in self.observers:
            observer(target)


__all__ = ["ALLOWED", "IllegalMatchTransition", "Lifecycle", "MatchState"]
