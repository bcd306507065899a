"""Rules on a match's timing that hold whatever file it comes from (game.json, a schedule's
``game_defaults``).

Each half must keep :data:`MIN_PLAYING_S` simulated seconds of PLAYING after its READY and SET
(the worst case: a half clock that runs through READY and SET); otherwise the match ends 0:0
without a kick.
"""

from __future__ import annotations

from orchestrator.config.model import Timing

SET_TO_PLAY_S = 5.0
"""Simulated seconds of SET before PLAYING (the automatic referee's, as the GameController's)."""
MIN_PLAYING_S = 10.0
"""Simulated seconds of PLAYING each half must keep after READY and SET."""


def timing_problems(timing: Timing, *, knockout: bool = False) -> list[tuple[str, str, str]]:
    """(field under ``timing``, what is wrong, what is expected) for each half too short."""
    problems = []
    halves = [("half_duration_s", timing.half_duration_s, "half")]
    if knockout:
        halves.append(("overtime_half_duration_s", timing.overtime_half_duration_s,
                       "half of extra time"))
    for name, half, what in halves:
        left = half - timing.ready_duration_s - SET_TO_PLAY_S
        if left >= MIN_PLAYING_S:
            continue
        problems.append((
            name,
            f"READY ({timing.ready_duration_s:g} s) plus SET ({SET_TO_PLAY_S:g} s) leaves "
            f"{max(left, 0.0):g} s of play in a {what} of {half:g} s; at least "
            f"{MIN_PLAYING_S:g} s are needed",
            f"ready_duration_s + {SET_TO_PLAY_S:g} s (SET) + {MIN_PLAYING_S:g} s <= {name}",
        ))
    return problems
