"""The servo of each motor of a team model: its catalogue entry (at most the entry's figures),
or the manifest's free-form figures; and the rule book's verdict on them."""

from __future__ import annotations

from simulator.errors import ModelProblem
from simulator.world.robots.model import MotorSpec
from simulator.world.robots.team.entries import Manifest, MotorEntry
from simulator.world.servos import find_servo

RULE = "servos from the league catalogue"
ARMATURE_BOUND = 2.0
"""``joint_armature`` may be at most this factor above or below a catalogue servo's armature
(its reflected rotor inertia): a gearbox's inertia is known to within that, not more."""
ARMATURE_RULE = "armature within a factor 2 of the catalogue servo's reflected rotor inertia"


def armature_of(entry: MotorEntry, manifest: Manifest) -> float:
    """The joint's armature: the catalogue servo's, or the manifest's ``joint_armature`` held
    within :data:`ARMATURE_BOUND` of it (free-form motors: the manifest's, else 0)."""
    found = find_servo(entry.servo) if entry.servo else None
    wanted = manifest.joint_armature
    if found is None:
        return wanted or 0.0
    own = found.armature_kg_m2
    if wanted is None:
        return own
    return min(max(wanted, own / ARMATURE_BOUND), own * ARMATURE_BOUND)


def motor_spec(entry: MotorEntry, manifest: Manifest) -> MotorSpec:
    """The motor's figures (joint range 0: :func:`dataclasses.replace` it in). A catalogue
    servo keeps its figures where the entry asks for more (the rule book refuses that); the
    manifest's ``joint_damping`` / ``joint_frictionloss`` replace the servo's friction."""
    found = find_servo(entry.servo) if entry.servo else None
    if found is not None:
        spec = MotorSpec.from_servo(entry.name, 0.0, 0.0, found)
        torque = min(entry.max_torque_nm or spec.max_torque_nm, spec.max_torque_nm)
        velocity = min(entry.max_velocity_rad_s or spec.max_velocity_rad_s, spec.max_velocity_rad_s)
    else:
        spec = MotorSpec(
            name=entry.name, lower_rad=0.0, upper_rad=0.0, max_torque_nm=1.0, max_velocity_rad_s=1.0
        )
        torque = entry.max_torque_nm or 1.0
        velocity = entry.max_velocity_rad_s or 1.0
    friction = manifest.joint_frictionloss
    damping = manifest.joint_damping
    return MotorSpec(
        name=entry.name,
        lower_rad=0.0,
        upper_rad=0.0,
        max_torque_nm=torque,
        max_velocity_rad_s=velocity,
        full_torque_speed_rad_s=min(spec.full_torque_speed_rad_s, velocity * 0.9),
        static_friction_nm=spec.static_friction_nm if friction is None else friction,
        damping_nm_s_per_rad=spec.damping_nm_s_per_rad if damping is None else damping,
        backlash_rad=spec.backlash_rad,
        encoder_resolution_rad=spec.encoder_resolution_rad,
        servo=found.id if found is not None else "",
        armature_kg_m2=armature_of(entry, manifest),
    )


def servo_problems(manifest: Manifest, *, official: bool) -> list[ModelProblem]:
    """Motors above their catalogue entry (errors), free-form motors and free-form friction or
    gains (warnings in friendlies, errors when ``official``)."""
    free = "error" if official else "warning"
    match = (
        "not for an official match"
        if official
        else ("for friendlies only (refused in official matches)")
    )
    out: list[ModelProblem] = []
    for i, entry in enumerate(manifest.motors):
        out += _motor_problems(manifest, i, entry, free=free, match=match)
    if manifest.joint_armature is not None:
        out += _armature_problems(manifest, manifest.joint_armature)
    for key, value in (
        ("joint_damping", manifest.joint_damping),
        ("joint_frictionloss", manifest.joint_frictionloss),
    ):
        if value is not None:
            out.append(
                ModelProblem(
                    source=str(manifest.path),
                    where=f"/{key}",
                    severity=free,
                    reason=f"{key} {value:g} replaces the catalogue servos' friction: {match} "
                    f"(rule: {RULE})",
                )
            )
    return out


def _motor_problems(
    manifest: Manifest, i: int, entry: MotorEntry, *, free: str, match: str
) -> list[ModelProblem]:
    """Motor ``i``: free-form (severity ``free``), above its catalogue servo, free-form gains.
    ``match``: whom free-form figures are for."""
    source = str(manifest.path)
    at = f"/motors/{i}"
    out: list[ModelProblem] = []
    found = find_servo(entry.servo) if entry.servo else None
    if found is None:
        out.append(
            ModelProblem(
                source=source,
                where=f"{at}/servo",
                severity=free,
                reason=f"{entry.name} (joint {entry.joint}) names no catalogue servo: "
                f"free-form max_torque_nm {entry.max_torque_nm} and max_velocity_rad_s "
                f"{entry.max_velocity_rad_s} are {match} (rule: {RULE})",
            )
        )
    else:
        for key, value, limit in (
            ("max_torque_nm", entry.max_torque_nm, found.stall_torque_nm),
            ("max_velocity_rad_s", entry.max_velocity_rad_s, found.no_load_speed_rad_s),
        ):
            if value is not None and value > limit * (1 + 1e-6):
                out.append(
                    ModelProblem(
                        source=source,
                        where=f"{at}/{key}",
                        reason=f"{entry.name} (joint {entry.joint}): {key} {value:g} is above "
                        f"the catalogue's {limit:.4g} for {found.id} (rule: {RULE})",
                    )
                )
    for key in entry.free_gains:
        out.append(
            ModelProblem(
                source=source,
                where=f"{at}/{key}",
                severity=free,
                reason=f"{entry.name}: free-form gain {key} is {match} and has no effect: "
                f"position control is Webots' (P, I, D from MotorPID; rule: {RULE})",
            )
        )
    return out


def _armature_problems(manifest: Manifest, wanted: float) -> list[ModelProblem]:
    """``joint_armature`` outside :data:`ARMATURE_BOUND` of a catalogue servo's own."""
    out: list[ModelProblem] = []
    for entry in manifest.motors:
        found = find_servo(entry.servo) if entry.servo else None
        if found is None:
            continue
        own = found.armature_kg_m2
        if not own / ARMATURE_BOUND * (1 - 1e-6) <= wanted <= own * ARMATURE_BOUND * (1 + 1e-6):
            out.append(
                ModelProblem(
                    source=str(manifest.path),
                    where="/joint_armature",
                    reason=f"{wanted:g} kg m^2 on {entry.name} ({found.id}) is outside "
                    f"{own / ARMATURE_BOUND:.4g}-{own * ARMATURE_BOUND:.4g} kg m^2, a factor "
                    f"{ARMATURE_BOUND:g} around the servo's {own:.4g} (rule: {ARMATURE_RULE}; "
                    "leave joint_armature out to take each servo's own)",
                )
            )
    return out
