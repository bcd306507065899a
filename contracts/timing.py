"""Match timing: the one source every way of making a match takes its timing from.

Official matches, ``hlvs scrimmage`` (local and on the Slurm pool), the service's test matches,
``hlvs compose``, tournament schedules and the Gymnasium environments all start from a preset of
this module and pass :func:`check_half` (or :func:`fit_ready` for quick tests), so that a game
whose halves leave no time to play is refused before it starts.

The rule counts the clock that really runs: the game clock stands still in READY and SET before
each half's kick-off (the league's GameController, ``AdvancedData.getRemainingGameTime``:
``timeBeforeCurrentGameState == 0``), so a half keeps all of its time for PLAYING until a goal
is scored, however long its READY; each half must be at least :data:`MIN_PLAYING_S` simulated
seconds. READY and SET after a goal count as played, but a goal is football already played.
The league's own tests play 20 s halves with the rules' 45 s READY (``--halftimeduration 20``).

After the match, :func:`played_enough` tells a match that played football from one that did not:
no half reached PLAYING, or fewer than :data:`MIN_PLAYING_S` seconds were played in all.
"""

from __future__ import annotations

from dataclasses import dataclass

SET_TO_PLAY_S = 5.0
"""Simulated seconds from SET to PLAYING (the automatic referee's, as the GameController's)."""
MIN_PLAYING_S = 10.0
"""The documented minimum of play: simulated seconds of PLAYING each half must keep (its length:
READY and SET before the kick-off stop the clock), and that a match must have played in all to
count as played. A game sets its own with
``timing.minimum_play_s``; 0 marks a match not meant to play football (a test of the match's
lifecycle: containers, logs, signals), which is neither refused nor failed for want of play."""
REMOVAL_PENALTY_S = 30.0
"""A removal penalty's simulated seconds: the league GameController's for every penalty its
referee gives (``Penalties.java:15-17``, ``HL_BALL_MANIPULATION``, ``HL_PHYSICAL_CONTACT``,
``HL_PICKUP_OR_INCAPABLE``: 30), and the league referee's ``REMOVAL_PENALTY_TIMEOUT``."""
MIN_READY_S = 5.0
"""The shortest READY a quick test uses (robots need a moment to stand up)."""


@dataclass(frozen=True, slots=True, kw_only=True)
class TimingPreset:
    """The timing of one way of making a match. Play durations are simulated seconds; the waits
    before the first READY, at half time and after the game (grace) are wall seconds."""

    half_duration_s: float
    ready_duration_s: float
    wait_before_first_ready_s: float
    half_time_break_s: float
    grace_period_s: float

    @property
    def playing_per_half_s(self) -> float:
        return playing_per_half_s(self.half_duration_s)


OFFICIAL = TimingPreset(half_duration_s=600.0, ready_duration_s=45.0,
                        wait_before_first_ready_s=120.0, half_time_break_s=15.0,
                        grace_period_s=120.0)
"""The league's rules: 10 min halves, 45 s READY (game.json defaults)."""
SCRIMMAGE = TimingPreset(half_duration_s=40.0, ready_duration_s=20.0,
                         wait_before_first_ready_s=3.0, half_time_break_s=1.0, grace_period_s=5.0)
"""``hlvs scrimmage`` (local or ``--pool slurm``): 40 s of PLAYING per half when no goal is
scored (READY and SET before a half's kick-off stop the clock), about 65 s simulated."""
ADULT_SCRIMMAGE = TimingPreset(half_duration_s=60.0, ready_duration_s=30.0,
                               wait_before_first_ready_s=3.0, half_time_break_s=1.0,
                               grace_period_s=5.0)
"""``hlvs scrimmage`` on the adult field: :data:`SCRIMMAGE`'s half and READY times 1.5. The adult
field is 14 m long against the kid's 9 m and the adult stub walks at the kid's 0.4 m/s, so every
walk takes half again as long: with the kid's timing a striker reached its kick-off spot at the
end of READY without having turned, kicked off late, and a 40 s half ended about when it reached
the kick-off pass (4 matches, 0 goals, one shot each)."""
TEST_MATCH = TimingPreset(half_duration_s=40.0, ready_duration_s=10.0,
                          wait_before_first_ready_s=3.0, half_time_break_s=1.0,
                          grace_period_s=5.0)
"""The submission service's test matches: 40 s of PLAYING per half before any goal (READY and SET
before the kick-off stop the clock), at least 25 s when the clock runs through them (30 s halves
with a 10 s READY, the clock running, left a robot walking at 0.2 m/s from its touch line too
little time to reach the ball)."""
ENVIRONMENT = TimingPreset(half_duration_s=60.0, ready_duration_s=15.0,
                           wait_before_first_ready_s=1.0, half_time_break_s=0.0,
                           grace_period_s=0.0)
"""The Gymnasium match environments (simulated waits)."""


class TimingError(ValueError):
    """A timing that leaves a half no time to play; the message is a sentence saying why."""


def playing_per_half_s(half_s: float) -> float:
    """Simulated seconds of PLAYING a half keeps until a goal: all of it, since the clock stands
    still in READY and SET before the half's kick-off, however long they last."""
    return half_s


def timing_problem(half_s: float, *, minimum_s: float = MIN_PLAYING_S,
                   what: str = "half") -> str | None:
    """Why a half of ``half_s`` cannot be played, or None: it keeps less than ``minimum_s`` of
    PLAYING. ``minimum_s`` 0: a match not meant to play (a lifecycle test), never a problem."""
    left = playing_per_half_s(half_s)
    if minimum_s <= 0 or left >= minimum_s:
        return None
    return (f"a {what} of {half_s:g} s leaves {max(left, 0.0):g} s of play (the clock stands "
            f"still in READY and SET before its kick-off); at least {minimum_s:g} s are needed "
            f"(a {what} of at least {minimum_s:g} s)")


def check_half(half_s: float, *, minimum_s: float = MIN_PLAYING_S) -> None:
    """Raise :class:`TimingError` when the half keeps less than the minimum of play."""
    problem = timing_problem(half_s, minimum_s=minimum_s)
    if problem is not None:
        raise TimingError(problem)


def fit_ready(half_s: float, ready_s: float, *,
              minimum_s: float = MIN_PLAYING_S) -> tuple[float, str | None]:
    """For quick tests: the READY to use and a warning when it was changed. READY never eats
    into the half (the clock stands still in it), so it is kept; raises :class:`TimingError`
    when the half itself is shorter than the minimum of play.
    """
    problem = timing_problem(half_s, minimum_s=minimum_s)
    if problem is not None:
        raise TimingError(f"a half of {half_s:g} s is too short to play: {problem}")
    return ready_s, None


def played_enough(halves_playing: tuple[int, ...] | list[int], playing_s: float,
                  minimum_s: float = MIN_PLAYING_S) -> bool:
    """True when a match played football: a half reached PLAYING and at least ``minimum_s``
    seconds were played (``minimum_s`` 0: always, for a match not meant to play)."""
    return minimum_s <= 0 or (bool(halves_playing) and playing_s >= minimum_s)


__all__ = [
    "ADULT_SCRIMMAGE",
    "ENVIRONMENT",
    "MIN_PLAYING_S",
    "MIN_READY_S",
    "OFFICIAL",
    "REMOVAL_PENALTY_S",
    "SCRIMMAGE",
    "SET_TO_PLAY_S",
    "TEST_MATCH",
    "TimingError",
    "TimingPreset",
    "check_half",
    "fit_ready",
    "played_enough",
    "playing_per_half_s",
    "timing_problem",
]
