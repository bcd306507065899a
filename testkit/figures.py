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



__all__ = ["Target", "median_figures"]
