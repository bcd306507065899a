"""MuJoCo soccer world, robot API server, recorder and telemetry of hlvs-runner."""

from __future__ import annotations

from simulator.errors import (
    ApiError,
    PhysicsDivergence,
    SimulatorError,
    SpecError,
    UnknownModelError,
)
from simulator.spec import MatchSpec, NetworkSpec, PlayerSpec, Pose, TeamSpec, TimingSpec

__all__ = [
    "ApiError",
    "MatchSpec",
    "NetworkSpec",
    "PhysicsDivergence",
    "PlayerSpec",
    "Pose",
    "SimulatorError",
    "SpecError",
    "TeamSpec",
    "TimingSpec",
    "UnknownModelError",
]
