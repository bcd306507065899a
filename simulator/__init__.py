"""MuJoCo soccer world, robot API server, recorder and telemetry of hlvs-runner.

What the simulator reads and writes (``match_spec.json``, ``sim_result.json``, telemetry) is
typed in the ``contracts`` package.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from simulator.errors import (
    ApiError,
    ModelError,
    PhysicsDivergence,
    ReplayError,
    SimulatorError,
    UnknownModelError,
)

if TYPE_CHECKING:
    from simulator.league_tests import LeagueOutcome, LeagueTestOutcome, run_league_scenario
    from simulator.match_setup import referee_config
    from simulator.native_build import NativeBuildError, build_native
    from simulator.traffic import read_stats

__all__ = [
    "ApiError",
    "LeagueOutcome",
    "LeagueTestOutcome",
    "ModelError",
    "NativeBuildError",
    "PhysicsDivergence",
    "ReplayError",
    "SimulatorError",
    "UnknownModelError",
    "build_native",
    "read_stats",
    "referee_config",
    "run_league_scenario",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "simulator.league_tests": ("LeagueOutcome", "LeagueTestOutcome", "run_league_scenario"),
        "simulator.match_setup": ("referee_config",),
        "simulator.native_build": ("NativeBuildError", "build_native"),
        "simulator.traffic": ("read_stats",),
    })
