"""Team robot models named in team_config.json: found, checked and mounted into the simulator.

A player's ``model`` is a built-in name (``kid-default``, ``adult-default``) or the path of a
model package folder (a folder with ``robot_model.json``, see configs/README.md), relative to the
team file. The package is checked against the rule book when the team file is loaded (a model
that breaks a rule is an error: it cannot be used in a match) and mounted read-only into the
simulator container, where the match spec names it by its container path.
"""

from __future__ import annotations

import hashlib
from pathlib import Path
from typing import TYPE_CHECKING

from orchestrator.errors import Problem

if TYPE_CHECKING:
    from simulator.world.robots.team import Measurements

MODEL_MANIFEST = "robot_model.json"
MODELS_TARGET = "/opt/hlvs/team-models"


BUILT_IN_MODELS = ("adult-default", "kid-default")


def is_model_path(name: str) -> bool:
    """True when ``name`` names a model package folder rather than a built-in model."""
    return name not in BUILT_IN_MODELS


def is_model_package(path: Path) -> bool:
    """A folder holding a model manifest, or the manifest itself."""
    return (path.is_dir() and (path / MODEL_MANIFEST).is_file()) or path.name == MODEL_MANIFEST


def container_path(host_folder: str) -> str:
    """Where the simulator container sees the model package ``host_folder`` (absolute)."""
    digest = hashlib.sha256(host_folder.encode()).hexdigest()[:12]
    return f"{MODELS_TARGET}/{Path(host_folder).name}-{digest}"


def spec_model(model: str) -> str:
    """The model name the match spec carries: built-in names as they are, packages by their
    container path."""
    return container_path(model) if is_model_path(model) else model


def check_model(
    path: Path, *, official: bool = False
) -> tuple[list[Problem], Measurements | None]:
    """Problems and measurements of a model package (None when it cannot even be loaded);
    free-form servos are warnings, or errors when ``official``. Imports the simulator's model
    loader (and MuJoCo) on first use."""
    from simulator import ModelError
    from simulator.world.robots.team import check, load_team_model, unserved_cameras

    folder = path if path.is_dir() else path.parent
    try:
        model = load_team_model(folder)
        measurements, found = check(model, official=official)
    except ModelError as exc:
        return [Problem(p.source, p.where, p.reason) for p in exc.problems], None
    found = [*found, *unserved_cameras(model.manifest)]
    return [
        Problem(p.source, p.where, p.reason, severity=p.severity) for p in found
    ], measurements


def model_devices(path: Path) -> dict[str, list[str]]:
    """The device names a model package's robot answers to on the robot API, by kind
    (``motor``, ``position_sensor``, ``accelerometer``, ``gyro``, ``camera``, ``force``); empty
    when the package cannot be loaded (:func:`check_model` says why)."""
    from simulator import ModelError
    from simulator.world.robots.team import load_team_model

    folder = path if path.is_dir() else path.parent
    try:
        devices = load_team_model(folder).devices
    except ModelError:
        return {}
    return {str(kind): list(names) for kind, names in devices.by_kind().items()}


def describe(measurements: Measurements) -> str:
    """One line of the measurements, rounded as ``hlvs check`` shows them."""
    m = measurements.rounded()
    return (
        f"H {m.height_m} m, Hleg {m.leg_m} m, Hhead {m.head_m} m, Harm {m.arm_m} m, "
        f"foot {m.foot_length_m} x {m.foot_width_m} m, mass {m.mass_kg} kg "
        f"(servos {m.servo_mass_kg} kg; {_split(m.mass_split_kg)}), "
        f"{m.motors} motors, {m.cameras} camera(s), "
        f"reach per chain {_split(m.arm_chains_m, ' m')}, "
        f"{round(100 * m.collision_coverage, 1):g} % of the mass in collision shapes"
    )


def _split(values: dict[str, float], unit: str = "") -> str:
    return ", ".join(f"{k} {v:g}{unit}" for k, v in values.items())
