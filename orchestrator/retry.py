"""Retries of transient failures with exponential backoff and full jitter.

The n-th retry waits a random time in ``[0, min(cap_s, base_s * 2**n)]`` ("full jitter"), so that
many clients failing together do not come back together. Only errors the caller calls transient
are retried; the last one is raised when every attempt failed.
"""

from __future__ import annotations

import logging
import random
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import TypeVar

log = logging.getLogger(__name__)

T = TypeVar("T")


@dataclass(frozen=True, slots=True, kw_only=True)
class Backoff:
    """How often and how long to retry."""

    attempts: int = 4  # in total, the first one included
    base_s: float = 1.0
    cap_s: float = 30.0
    sleep: Callable[[float], None] = field(default=time.sleep, repr=False, compare=False)
    rng: random.Random = field(default_factory=random.Random, repr=False, compare=False)

    def __post_init__(self) -> None:
        if self.attempts < 1 or self.base_s < 0 or self.cap_s < 0:
            raise ValueError("Backoff: attempts >= 1 and non-negative delays expected")

    def delay_s(self, retry: int) -> float:
        """Seconds before retry number ``retry`` (0 for the first retry)."""
        return self.rng.uniform(0.0, min(self.cap_s, self.base_s * 2**retry))


def retry(
    call: Callable[[], T],
    *,
    transient: Callable[[Exception], bool],
    backoff: Backoff,
    what: str,
    on_retry: Callable[[int, Exception, float], None] | None = None,
    wait_hint: Callable[[Exception], float | None] | None = None,
) -> T:
    """``call()``, again after a backoff while it raises an error ``transient`` accepts.

    ``wait_hint(error)`` may name a wait the server asked for (``Retry-After``); the backoff then
    waits at least that long, at most ``cap_s``.
    """
    for attempt in range(backoff.attempts):
        try:
            return call()
        except Exception as exc:
            if not transient(exc) or attempt + 1 >= backoff.attempts:
                raise
            delay = backoff.delay_s(attempt)
            asked = wait_hint(exc) if wait_hint is not None else None
            if asked is not None:
                delay = min(max(delay, asked), backoff.cap_s)
            log.warning(
                "%s failed (attempt %d of %d): %s; retrying in %.1f s",
                what, attempt + 1, backoff.attempts, exc, delay,
            )
            if on_retry is not None:
                on_retry(attempt + 1, exc, delay)
            backoff.sleep(delay)
    raise AssertionError("unreachable")  # attempts >= 1


__all__ = ["Backoff", "retry"]
