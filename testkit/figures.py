"""Benchmark figures: the median of repeated runs and the targets they are judged against
(shared by ``hlvs bench report`` and its tests)."""

from __future__ import annotations

import os
import statistics
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from contracts.timing import OFFICIAL, SET_TO_PLAY_S


@dataclass(frozen=True, slots=True)
class Target:
    figure: str
    minimum: float | None = None
    maximum: float | None = None

    def met(self, value: float) -> bool:
        if self.minimum is not None and value < self.minimum:
            return False
        return self.maximum is None or value <= self.maximum

    def scaled(self, factor: float) -> Target:
        """The same target with its bound multiplied by ``factor`` (three decimals)."""
        minimum = None if self.minimum is None else round(self.minimum * factor, 3)
        maximum = None if self.maximum is None else round(self.maximum * factor, 3)
        return Target(self.figure, minimum, maximum)

    def to_dict(self) -> dict[str, str | float | None]:
        """``{"figure": name, "min" or "max": bound}``."""
        bound = {"min": self.minimum} if self.minimum is not None else {"max": self.maximum}
        return {"figure": self.figure, **bound}


# The targets of ``hlvs bench report``, per kind: the performance goals.
TARGETS = {
    "sim": Target("ratio", minimum=0.95),
    "async": Target("ratio_interleaved", minimum=0.92),
    "lockstep": Target("ratio_interleaved", minimum=0.85),
    # lockstep with clients written like the league's (no TCP_NODELAY, a request in two writes)
    "lockstep_league": Target("ratio_interleaved", minimum=0.85),
    "pipelined": Target("ratio_interleaved", minimum=0.92),
    "cameras": Target("real_time_factor", minimum=1.0),
    "bringup": Target("bringup_s", maximum=3.0),
}

# ``bench api --flood``: the other robots' pace with a robot flooding its port over their pace
# without it (``ratio_interleaved``, 1.0: the flood costs them nothing; at least 0.8)
FLOOD_TARGET = Target("ratio_interleaved", minimum=0.8)


def judged(target: Target, figures: Mapping[str, object]) -> dict[str, object]:
    """``target`` and whether ``figures`` meet it (None: the figure is missing), to add to a
    benchmark's JSON beside the figures."""
    value = figures.get(target.figure)
    met = target.met(value) if isinstance(value, int | float) else None
    return {"target": target.to_dict(), "meets_target": met}


# The speed of the bare 8-robot ``mj_step`` loop (times real time) of the machine the cameras' and
# the bring-up's targets are set for. Both depend on the machine's speed, so on another machine
# their bounds scale by its own bare loop (``bench sim``'s ``bare_real_time_factor``): the
# cameras' minimum with it, the bring-up's maximum against it.
REFERENCE_BARE_REAL_TIME_FACTOR = 12.0
MACHINE_SCALED = {"cameras": "with", "bringup": "against"}


def machine_target(kind: str, bare_real_time_factor: float | None) -> Target | None:
    """The target of ``kind`` on a machine whose bare loop runs ``bare_real_time_factor`` times
    real time (None: not measured, the reference machine's bound)."""
    target = TARGETS.get(kind)
    how = MACHINE_SCALED.get(kind)
    if target is None or how is None or not bare_real_time_factor:
        return target
    speed = bare_real_time_factor / REFERENCE_BARE_REAL_TIME_FACTOR
    return target.scaled(speed if how == "with" else 1.0 / speed)


# A match at the league's timing (``contracts.timing.OFFICIAL``): simulated seconds without a goal
# (two halves of 600 s of PLAYING, each after a 45 s READY and SET_TO_PLAY_S of SET; the clock
# stands still in both) and wall seconds the referee waits whatever the speed (before the first
# READY, at half time)
LEAGUE_MATCH_SIM_S = 2 * (OFFICIAL.half_duration_s + OFFICIAL.ready_duration_s + SET_TO_PLAY_S)
LEAGUE_MATCH_WAITS_S = OFFICIAL.wait_before_first_ready_s + OFFICIAL.half_time_break_s


def league_match_figures(
    real_time_factor: float, outside_play_s: float, cpus: int
) -> dict[str, float]:
    """What a match of the league's length costs on this machine, from a short bench match:
    ``real_time_factor`` (its simulator's), ``outside_play_s`` (its wall seconds outside the
    game: starting the containers, the robots connecting, stopping, collecting) and ``cpus``
    (the host's, all of which the match may use). The game is paced to real time at most, as
    the league's are: ``league_match_wall_s`` is ``outside_play_s`` plus the referee's wall
    waits plus :data:`LEAGUE_MATCH_SIM_S` at ``min(real_time_factor, 1)``;
    ``matches_per_core_hour`` is 3600 over that times ``cpus``."""
    if real_time_factor <= 0 or cpus < 1:
        raise ValueError(f"expected a real-time factor above 0 and at least one CPU, got "
                         f"{real_time_factor} and {cpus}")
    wall = outside_play_s + LEAGUE_MATCH_WAITS_S + LEAGUE_MATCH_SIM_S / min(real_time_factor, 1.0)
    return {
        "wall_s_per_sim_minute": round(60.0 / real_time_factor, 2),
        "league_match_wall_s": round(wall, 1),
        "matches_per_core_hour": round(3600.0 / (wall * cpus), 3),
    }


def median_figures(runs: Sequence[Mapping[str, object]]) -> dict[str, float]:
    """Per numeric figure, the median over the runs (figure name -> value) that did not fail."""
    good = [r for r in runs if "error" not in r]
    keys = sorted({k for r in good for k, v in r.items() if isinstance(v, int | float)
                   and not isinstance(v, bool)})  # fmt: skip
    medians: dict[str, float] = {}
    for key in keys:
        values = [v for r in good if isinstance(v := r.get(key), int | float)]
        if values:
            medians[key] = round(statistics.median(values), 3)
    return medians


def report_rounds(kinds: Sequence[str], runs: Mapping[str, int]) -> list[list[str]]:
    """The order ``hlvs bench report`` runs its kinds in: rounds of every kind that still has
    runs to do (``runs``: how many each wants, at least one), interleaved so that the machine's
    load falls on all alike, until each has all its own (a kind wanting more than the others,
    the match's ``--match-repeats``, goes on alone)."""
    wanted = {kind: max(1, runs.get(kind, 1)) for kind in kinds}
    rounds = max(wanted.values(), default=0)
    return [[kind for kind in kinds if wanted[kind] > turn] for turn in range(rounds)]


def cpu_times(stat_text: str) -> tuple[int, int] | None:
    """(stolen, total) clock ticks of all CPUs from the text of ``/proc/stat`` (its ``cpu``
    line: user, nice, system, idle, iowait, irq, softirq, steal; guest time is inside user);
    None where the text has no such line."""
    for line in stat_text.splitlines():
        fields = line.split()
        if fields and fields[0] == "cpu" and len(fields) >= 9:
            ticks = [int(f) for f in fields[1:9]]
            return ticks[7], sum(ticks)
    return None


def steal_share(before: tuple[int, int] | None, after: tuple[int, int] | None) -> float | None:
    """The share of the CPUs' time between two :func:`cpu_times` readings that the hypervisor
    gave to other machines (steal time): 0 on a machine of its own; None without both
    readings."""
    if before is None or after is None or after[1] <= before[1]:
        return None
    return round((after[0] - before[0]) / (after[1] - before[1]), 3)


def process_cpu_s(pid: int | None) -> float | None:
    """CPU seconds (user and system) process ``pid`` has used so far, from ``/proc``; None
    where it cannot be read (the process is gone, or no ``/proc``)."""
    try:
        with open(f"/proc/{pid}/stat", encoding="ascii") as stat:
            fields = stat.read().rsplit(")", 1)[1].split()
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


__all__ = [
    "FLOOD_TARGET",
    "LEAGUE_MATCH_SIM_S",
    "LEAGUE_MATCH_WAITS_S",
    "MACHINE_SCALED",
    "REFERENCE_BARE_REAL_TIME_FACTOR",
    "TARGETS",
    "Target",
    "cpu_times",
    "judged",
    "league_match_figures",
    "machine_target",
    "median_figures",
    "process_cpu_s",
    "report_rounds",
    "steal_share",
]
