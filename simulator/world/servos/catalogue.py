"""The league servo catalogue: one JSON file per servo model in this folder, with the maker's
datasheet figures at each voltage the datasheet lists (its page is the entry's ``source``).

An entry that a robot names is a voltage variant of a model, written ``MODEL@VOLTAGEV``
(``MX-106@14.8V``); a model alone names its highest-voltage variant. Adding a servo: copy a file
of the same family, take every figure from the maker's page, record the page as ``source``, and
run ``hlvs bench actuators --json`` (it measures the new entry against its figures).

Per model: ``aliases`` (optional: other names of the same servo, ``MX-64(2.0)``),
``gear_ratio``, ``backlash_rad``, ``encoder_resolution_rad`` (one encoder count at the output),
``mass_kg``, ``rotor_inertia_kg_m2`` (the motor's rotor and first gear stage; the joint's
armature, its reflected inertia, is that times the gear ratio squared:
:attr:`Servo.armature_kg_m2`; ``rotor_inertia_source`` says where the figure comes from, or how
it was estimated where the maker publishes none), ``static_friction_nm`` and
``viscous_damping_nm_s_per_rad`` (league defaults where the datasheet is silent;
``friction_source`` says which), and ``variants``: each with ``voltage_v``,
``stall_torque_nm``, ``no_load_speed_rpm`` and, for servos rated by a continuous point
instead of a stall torque, ``full_torque_speed_rpm`` (the torque is available in full up to that
speed, then falls linearly to the no-load speed).
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from functools import cache
from pathlib import Path

from simulator.errors import ModelError, ModelProblem

FOLDER = Path(__file__).resolve().parent
RPM = 2 * math.pi / 60  # rad/s per rev/min


@dataclass(frozen=True, slots=True, kw_only=True)
class Servo:
    """One catalogue entry: a servo model at one voltage."""

    id: str  # "MX-106@14.8V"
    model: str
    voltage_v: float
    stall_torque_nm: float
    no_load_speed_rad_s: float
    full_torque_speed_rad_s: float  # 0 for a line from the stall torque
    gear_ratio: float
    backlash_rad: float
    encoder_resolution_rad: float
    mass_kg: float
    static_friction_nm: float
    viscous_damping_nm_s_per_rad: float
    source: str
    rotor_inertia_kg_m2: float = 0.0

    @property
    def armature_kg_m2(self) -> float:
        """The rotor's inertia reflected through the gearbox: rotor inertia x gear ratio^2."""
        return self.rotor_inertia_kg_m2 * self.gear_ratio * self.gear_ratio

    def available_torque_nm(self, speed_rad_s: float) -> float:
        """The datasheet's torque at the output when turning at ``speed_rad_s`` (>= 0)."""
        speed = abs(speed_rad_s)
        if speed <= self.full_torque_speed_rad_s:
            return self.stall_torque_nm
        span = self.no_load_speed_rad_s - self.full_torque_speed_rad_s
        return max(
            0.0, self.stall_torque_nm * (1.0 - (speed - self.full_torque_speed_rad_s) / span)
        )

    def to_json(self) -> dict[str, str | float]:
        """The datasheet figures (numbers) with the servo's id, model and source (text)."""
        return {
            "id": self.id,
            "model": self.model,
            "voltage_v": self.voltage_v,
            "stall_torque_nm": self.stall_torque_nm,
            "no_load_speed_rad_s": round(self.no_load_speed_rad_s, 4),
            "full_torque_speed_rad_s": round(self.full_torque_speed_rad_s, 4),
            "gear_ratio": self.gear_ratio,
            "backlash_rad": self.backlash_rad,
            "encoder_resolution_rad": self.encoder_resolution_rad,
            "mass_kg": self.mass_kg,
            "rotor_inertia_kg_m2": self.rotor_inertia_kg_m2,
            "armature_kg_m2": round(self.armature_kg_m2, 6),
            "static_friction_nm": self.static_friction_nm,
            "viscous_damping_nm_s_per_rad": self.viscous_damping_nm_s_per_rad,
            "source": self.source,
        }


def _number(raw: Mapping[str, object], key: str, source: str, where: str) -> float:
    value = raw.get(key)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
        raise ModelError(
            [
                ModelProblem(
                    source=source, where=f"{where}/{key}", reason=f"{value!r} is not a number >= 0"
                )
            ]
        )
    return float(value)


def _voltage_label(voltage_v: float) -> str:
    return f"{voltage_v:g}V"


def _load(path: Path) -> list[Servo]:
    source = str(path)
    try:
        raw = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, json.JSONDecodeError) as exc:
        raise ModelError(
            [ModelProblem(source=source, where="", reason=f"not JSON: {exc}")]
        ) from None
    model = raw.get("model")
    if not isinstance(model, str) or not model:
        raise ModelError([ModelProblem(source=source, where="/model", reason="expected a name")])
    common = {
        key: _number(raw, key, source, "")
        for key in (
            "gear_ratio",
            "backlash_rad",
            "encoder_resolution_rad",
            "mass_kg",
            "rotor_inertia_kg_m2",
            "static_friction_nm",
            "viscous_damping_nm_s_per_rad",
        )
    }
    variants = raw.get("variants")
    if not isinstance(variants, list) or not variants:
        raise ModelError(
            [ModelProblem(source=source, where="/variants", reason="expected a non-empty array")]
        )
    out = []
    for i, variant in enumerate(variants):
        where = f"/variants/{i}"
        if not isinstance(variant, dict):
            raise ModelError(
                [ModelProblem(source=source, where=where, reason="expected an object")]
            )
        voltage = _number(variant, "voltage_v", source, where)
        no_load = _number(variant, "no_load_speed_rpm", source, where) * RPM
        corner = float(variant.get("full_torque_speed_rpm", 0.0)) * RPM
        if not 0 <= corner < no_load:
            raise ModelError(
                [
                    ModelProblem(
                        source=source,
                        where=f"{where}/full_torque_speed_rpm",
                        reason="must be below the no-load speed",
                    )
                ]
            )
        out.append(
            Servo(
                id=f"{model}@{_voltage_label(voltage)}",
                model=model,
                voltage_v=voltage,
                stall_torque_nm=_number(variant, "stall_torque_nm", source, where),
                no_load_speed_rad_s=no_load,
                full_torque_speed_rad_s=corner,
                source=str(raw.get("source", "")),
                **common,
            )
        )
    return out


@cache
def catalogue() -> dict[str, Servo]:
    """Every catalogue entry by id (``MODEL@VOLTAGEV``), read once from the data files."""
    entries: dict[str, Servo] = {}
    for path in sorted(FOLDER.glob("*.json")):
        for servo in _load(path):
            entries[servo.id] = servo
    return entries


def servo_ids() -> tuple[str, ...]:
    return tuple(sorted(catalogue()))


@cache
def aliases() -> dict[str, str]:
    """Other names of a model (``aliases`` in its file: ``MX-64(2.0)``, the same servo with the
    protocol 2.0 firmware) -> the model."""
    out: dict[str, str] = {}
    for path in sorted(FOLDER.glob("*.json")):
        raw = json.loads(path.read_text(encoding="utf-8"))
        for alias in raw.get("aliases", []) if isinstance(raw, dict) else []:
            if isinstance(alias, str) and isinstance(raw.get("model"), str):
                out[alias] = raw["model"]
    return out


def find_servo(name: str) -> Servo | None:
    """The entry called ``name`` (``MX-106@14.8V``, or ``MX-106`` for its highest voltage; an
    alias such as ``MX-106(2.0)`` names the same entry)."""
    entries = catalogue()
    model, at, voltage = name.partition("@")
    if model in aliases():
        name = aliases()[model] + at + voltage
    if name in entries:
        return entries[name]
    variants = [s for s in entries.values() if s.model == name]
    return max(variants, key=lambda s: s.voltage_v) if variants else None


def servo(name: str) -> Servo:
    """:func:`find_servo` or :class:`KeyError` naming the catalogue's entries."""
    found = find_servo(name)
    if found is None:
        raise KeyError(f"{name!r} is not in the servo catalogue ({', '.join(servo_ids())})")
    return found
