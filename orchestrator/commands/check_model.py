"""`hlvs check MODEL_DIR`: a team robot model package against the rule book of its class.

The report holds the measurements (height, leg, head and arm lengths, foot size, mass, motors,
cameras) and one problem per broken rule or unusable part (file, where, the value, the limit and
the rule). The simulator's model loader (and MuJoCo) is imported only when a model is checked.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from orchestrator.errors import Problem

MODEL_MANIFEST = "robot_model.json"
MODEL_KIND = "robot model"


def is_model_package(path: Path) -> bool:
    """A folder holding a model manifest, or the manifest itself."""
    return (path.is_dir() and (path / MODEL_MANIFEST).is_file()) or path.name == MODEL_MANIFEST


def check_model(path: Path) -> tuple[list[Problem], dict[str, Any] | None]:
    """Problems and measurements (None when the package cannot even be loaded)."""
    from simulator.errors import ModelError
    from simulator.world.robots.team import load_team_model
    from simulator.world.robots.team.rulebook import check

    folder = path if path.is_dir() else path.parent
    try:
        measurements, found = check(load_team_model(folder))
    except ModelError as exc:
        return [Problem(p.source, p.where, p.reason) for p in exc.problems], None
    return [Problem(p.source, p.where, p.reason) for p in found], measurements.to_json()


def describe(measurements: dict[str, Any]) -> str:
    m = measurements
    return (
        f"H {m['height_m']} m, Hleg {m['leg_m']} m, Hhead {m['head_m']} m, Harm {m['arm_m']} m, "
        f"foot {m['foot_length_m']} x {m['foot_width_m']} m, mass {m['mass_kg']} kg, "
        f"{m['motors']} motors, {m['cameras']} camera(s)"
    )
