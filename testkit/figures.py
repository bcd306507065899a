"""Benchmark figures: the median of repeated runs and the targets they are judged against
(shared by ``hlvs bench report`` and its tests)."""

from __future__ import annotations

import statistics
from collections.abc import Mapping, Sequence
from dataclasses import dataclass


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



__all__ = [
    "FLOOD_TARGET",
    "MACHINE_SCALED",
    "REFERENCE_BARE_REAL_TIME_FACTOR",
    "TARGETS",
    "Target",
    "judged",
    "machine_target",
    "median_figures",
]
