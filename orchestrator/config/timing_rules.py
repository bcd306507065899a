"""Rules on a match's timing that hold whatever file it comes from (game.json, a schedule's
``game_defaults``), from :mod:`contracts.timing`: each half, and each half of a knockout's extra
time, keeps the game's minimum of play (``timing.minimum_play_s``); READY and SET before the
kick-off do not count (the clock stands still in them).
"""

from __future__ import annotations

from contracts import timing_problem
from orchestrator.config.model import Timing


def timing_problems(timing: Timing, *, knockout: bool = False) -> list[tuple[str, str, str]]:
    """(field under ``timing``, what is wrong, what is expected) for each half too short."""
    problems = []
    halves = [("half_duration_s", timing.half_duration_s, "half")]
    if knockout:
        halves.append(("overtime_half_duration_s", timing.overtime_half_duration_s,
                       "half of extra time"))
    for name, half, what in halves:
        problem = timing_problem(half, minimum_s=timing.minimum_play_s, what=what)
        if problem is not None:
            problems.append((name, problem, f"minimum_play_s ({timing.minimum_play_s:g} s) "
                             f"<= {name}"))
    return problems
