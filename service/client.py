"""The command-line client: ``hlvs submit|status|cancel|results|logs --server URL``."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


def register(sub: Any, guarded: Callable[[Any], Any]) -> None:
    """Added in a later slice."""


__all__ = ["register"]
