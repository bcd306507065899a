"""Orchestrator of hlvs-runner: configs, images, containers, match lifecycle, logs, schedule."""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from orchestrator.errors import (
    ConfigError,
    DeliveryError,
    EngineLost,
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

if TYPE_CHECKING:
    from orchestrator.compose import Subnets, collect_results, write_compose
    from orchestrator.console import progress
    from orchestrator.exitcodes import ExitCode
    from orchestrator.image_origin import local_name_reason
    from orchestrator.paths import file_in_the_way, user_path
    from orchestrator.private_files import (
        make_private_file,
        open_private_append,
        private_dir,
        write_private,
    )
    from orchestrator.project_images import build_all, ensure_image, project_image
    from orchestrator.pull import ResolvedImage, pull_game_images, resolve_team_images
    from orchestrator.scrimmage_options import add_gpu_argument, add_scrimmage_arguments
    from orchestrator.signals import stop_on_signals
    from orchestrator.telemetry import LiveView, ZenohTelemetry, subscriber_config

__all__ = [
    "ConfigError",
    "DeliveryError",
    "EngineLost",
    "EngineUnavailable",
    "ExitCode",
    "ImageError",
    "ImagePullError",
    "ImageTooLarge",
    "InfrastructureError",
    "LiveView",
    "MatchFailed",
    "OrchestratorError",
    "Problem",
    "ResolvedImage",
    "ScheduleError",
    "Subnets",
    "TeamImagesTooLarge",
    "ZenohTelemetry",
    "add_gpu_argument",
    "add_scrimmage_arguments",
    "build_all",
    "collect_results",
    "ensure_image",
    "file_in_the_way",
    "local_name_reason",
    "make_private_file",
    "open_private_append",
    "private_dir",
    "progress",
    "project_image",
    "pull_game_images",
    "resolve_team_images",
    "stop_on_signals",
    "subscriber_config",
    "user_path",
    "write_compose",
    "write_private",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "orchestrator.compose": ("Subnets", "collect_results", "write_compose"),
        "orchestrator.console": ("progress",),
        "orchestrator.exitcodes": ("ExitCode",),
        "orchestrator.image_origin": ("local_name_reason",),
        "orchestrator.paths": ("file_in_the_way", "user_path"),
        "orchestrator.private_files": (
            "make_private_file", "open_private_append", "private_dir", "write_private",
        ),
        "orchestrator.project_images": ("build_all", "ensure_image", "project_image"),
        "orchestrator.pull": ("ResolvedImage", "pull_game_images", "resolve_team_images"),
        "orchestrator.scrimmage_options": ("add_gpu_argument", "add_scrimmage_arguments"),
        "orchestrator.signals": ("stop_on_signals",),
        "orchestrator.telemetry": ("LiveView", "ZenohTelemetry", "subscriber_config"),
    })
