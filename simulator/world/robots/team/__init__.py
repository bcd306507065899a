"""Team robot models: a URDF or MJCF file with a manifest, checked and loaded into the world."""

from __future__ import annotations

from simulator.world.robots.team.manifest import MANIFEST_NAME, Manifest, load_manifest
from simulator.world.robots.team.model import TeamRobotModel, load_team_model

__all__ = ["MANIFEST_NAME", "Manifest", "TeamRobotModel", "load_manifest", "load_team_model"]
