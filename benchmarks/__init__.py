"""Benchmarks that print JSON, run as ``hlvs bench KIND`` (``python -m benchmarks KIND`` for
the simulator's own). Kept out of the production packages; the tests import nothing from here."""

from typing import TYPE_CHECKING

from contracts import lazy_exports

if TYPE_CHECKING:
    from benchmarks import (
        actuators,
        bringup,
        cli,
        delivery,
        envs,
        hog,
        models,
        pool,
        report,
        runtime,
        scrimmage,
        service,
        viewer,
    )

__all__ = [
    "actuators",
    "bringup",
    "cli",
    "delivery",
    "envs",
    "hog",
    "models",
    "pool",
    "report",
    "runtime",
    "scrimmage",
    "service",
    "viewer",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "benchmarks": (
            "actuators", "bringup", "cli", "delivery", "envs", "hog", "models", "pool", "report",
            "runtime", "scrimmage", "service", "viewer",
        ),
    })
