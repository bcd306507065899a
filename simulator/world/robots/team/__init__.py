"""Team robot models: a URDF or MJCF file with a manifest, checked and loaded into the world."""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from simulator.world.robots.team.devices import unserved_cameras
from simulator.world.robots.team.entries import Manifest
from simulator.world.robots.team.manifest import MANIFEST_NAME, load_manifest
from simulator.world.robots.team.model import TeamRobotModel, load_team_model

if TYPE_CHECKING:
    from simulator.world.robots.team.rulebook import Measurements, check

__all__ = [
    "MANIFEST_NAME",
    "Manifest",
    "Measurements",
    "TeamRobotModel",
    "check",
    "load_manifest",
    "load_team_model",
    "unserved_cameras",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "simulator.world.robots.team.rulebook": ("Measurements", "check"),
    })
