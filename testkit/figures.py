"""Benchmark figures: the median of repeated runs and the targets they are judged against
(shared by ``hlvs bench report`` and its tests)."""

from __future__ import annotations

import statistics
from dataclasses import dataclass
from typing import Any


@dataclass(frozen=True, slots=True)
class Target:
    figure: str
    minimum: float | None = None
    maximum: float | None = None

    def met(self, value: float) -> bool:
        if self.minimum is not None and value < self.minimum:
            return False
        return self.maximum is None or value <= self.maximum

    def to_dict(self) -> dict[str, Any]:
        bound = {"min": self.minimum} if self.minimum is not None else {"max": self.maximum}
        return {"figure": self.figure, **bound}


def median_figures(runs: list[dict[str, Any]]) -> dict[str, Any]:
    """Per numeric figure, the median over the runs that did not fail."""
    good = [r for r in runs if "error" not in r]
    keys = sorted({k for r in good for k, v in r.items() if isinstance(v, int | float)
                   and not isinstance(v, bool)})  # fmt: skip
    medians: dict[str, Any] = {}
    for key in keys:
        values = [r[key] for r in good if isinstance(r.get(key), int | float)]
        if values:
            medians[key] = round(statistics.median(values), 3)
    return medians



__all__ = ["Target", "median_figures"]
