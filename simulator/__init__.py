"""MuJoCo soccer world, robot API server, recorder and telemetry of hlvs-runner.

What the simulator reads and writes (``match_spec.json``, ``sim_result.json``, telemetry) is
typed in the ``contracts`` package.
"""

from __future__ import annotations

from simulator.errors import (
    ApiError,
    ModelError,
    PhysicsDivergence,
    ReplayError,
    SimulatorError,
    UnknownModelError,
)

__all__ = [
    "ApiError",
    "ModelError",
    "PhysicsDivergence",
    "ReplayError",
    "SimulatorError",
    "UnknownModelError",
]
