"""Orchestrator of hlvs-runner: configs, images, containers, match lifecycle, logs, schedule."""

from __future__ import annotations

from orchestrator.errors import (
    ConfigError,
    DeliveryError,
    EngineUnavailable,
    ImageError,
    ImagePullError,
    ImageTooLarge,
    InfrastructureError,
    MatchFailed,
    OrchestratorError,
    Problem,
    ScheduleError,
    TeamImagesTooLarge,
)

__all__ = [
    "ConfigError",
    "DeliveryError",
    "EngineUnavailable",
    "ImageError",
    "ImagePullError",
    "ImageTooLarge",
    "InfrastructureError",
    "MatchFailed",
    "OrchestratorError",
    "Problem",
    "ScheduleError",
    "TeamImagesTooLarge",
]
