"""A team model's device names, as its manifest gives them, and their checks.

The league's robot API finds devices by the names of the robot's Webots file (PROTO), and a
team's code asks for those names. A manifest names them as that file does: each motor's
``name``, its position sensor's ``sensor`` (default: the motor's name + ``sensor_suffix``, itself
``S`` by default as on the league's sample robot; bit-bots' Wolfgang uses ``_sensor``), each
IMU's ``accelerometer`` and ``gyro`` (default ``Accelerometer`` and ``Gyro`` for the first),
the camera's ``name`` and the keys of ``force_sensors``. Every name must be distinct across the
robot's devices (Webots finds the first of two devices with one name; the API could not tell
them apart), printable, 1 to :data:`MAX_NAME_CHARS` characters without a space at either end.

The force sensors' MJCF sensors are ``<prefix>/force:<name>`` (sites ``site:force:<name>``), so
no device name can clash with the simulator's own sensors and sites.
"""

from __future__ import annotations

from simulator.errors import ModelProblem
from simulator.world.robots.devices import DeviceNames, ImuNames
from simulator.world.robots.team.entries import ImuEntry, Manifest

MAX_NAME_CHARS = 100
RESERVED_MOTOR_NAMES = frozenset({"root"})  # the free base's joint, <prefix>/root


def force_mjcf(name: str) -> str:
    """The MJCF sensor (and, after ``site:``, site) name of a force sensor, without prefix."""
    return f"force:{name}"


def imus_of(manifest: Manifest) -> tuple[ImuEntry, ...]:
    """The manifest's IMUs, the first one the trunk's (``imu_link``)."""
    if manifest.imus:
        return manifest.imus
    return (ImuEntry(link=manifest.imu_link),)


def position_sensor_name(manifest: Manifest, motor: int) -> str:
    m = manifest.motors[motor]
    return m.sensor or f"{m.name}{manifest.sensor_suffix}"


def device_names(manifest: Manifest) -> DeviceNames:
    """What the robot answers to on the robot API (the first camera is the one served)."""
    forces = tuple(manifest.force_sensors)
    return DeviceNames(
        motors=tuple(m.name for m in manifest.motors),
        position_sensors=tuple(
            position_sensor_name(manifest, i) for i in range(len(manifest.motors))
        ),
        imus=tuple(ImuNames(accelerometer=i.accelerometer, gyro=i.gyro) for i in imus_of(manifest)),
        camera=manifest.cameras[0].name if manifest.cameras else "Camera",
        forces=forces,
        force_mjcf=tuple(force_mjcf(n) for n in forces),
    )


def _pointer_token(key: str) -> str:
    return key.replace("~", "~0").replace("/", "~1")


def _named(manifest: Manifest) -> list[tuple[str, str, str]]:
    """(name, what it names, JSON pointer) of every device name the manifest gives."""
    out: list[tuple[str, str, str]] = []
    for i, m in enumerate(manifest.motors):
        out.append((m.name, "a motor", f"/motors/{i}/name"))
    for i, m in enumerate(manifest.motors):
        if m.sensor:
            out.append((m.sensor, "a position sensor", f"/motors/{i}/sensor"))
        elif manifest.sensor_suffix:
            out.append(
                (
                    position_sensor_name(manifest, i),
                    "a position sensor (name + sensor_suffix)",
                    f"/motors/{i}/name",
                )
            )
    for imu in imus_of(manifest):
        out.append((imu.accelerometer, "an accelerometer", f"{imu.where}/accelerometer"))
        out.append((imu.gyro, "a gyro", f"{imu.where}/gyro"))
    for k, camera in enumerate(manifest.cameras):
        out.append((camera.name, "a camera", f"/cameras/{k}/name"))
    for name in manifest.force_sensors:
        out.append((name, "a force sensor", f"/force_sensors/{_pointer_token(name)}"))
    return out


def _bad_name(name: str) -> str | None:
    expected = f"expected 1 to {MAX_NAME_CHARS} printable characters, no space at either end"
    if not name:
        return f"an empty device name; {expected}"
    if len(name) > MAX_NAME_CHARS:
        return f"a device name of {len(name)} characters; {expected}"
    if not name.isprintable():
        bad = next(c for c in name if not c.isprintable())
        return f"{name!r} holds the unprintable character {bad!r}; {expected}"
    if name != name.strip():
        return f"{name!r} has a space at one end; {expected}"
    return None


def device_name_problems(manifest: Manifest) -> list[ModelProblem]:
    """Bad device names and names given to two devices, each naming the file, the pointer of
    the name and what was expected."""
    source = str(manifest.path)
    problems: list[ModelProblem] = []

    def bad(where: str, reason: str) -> None:
        problems.append(ModelProblem(source=source, where=where, reason=reason))

    if not manifest.sensor_suffix and not all(m.sensor for m in manifest.motors):
        bad(
            "/sensor_suffix",
            "an empty suffix gives each position sensor its motor's name; expected a suffix "
            "(the league's robots use S or _sensor) or a sensor name in every motor",
        )
    seen: dict[str, tuple[str, str]] = {}
    for name, what, where in _named(manifest):
        reason = _bad_name(name)
        if reason is not None:
            bad(where, reason)
            continue
        if what == "a motor" and name in RESERVED_MOTOR_NAMES:
            bad(where, f"{name!r} is the simulator's name of the robot's free base; "
                "expected another motor name")
        if name in seen:
            other_what, other_where = seen[name]
            if what == other_what == "a motor":
                continue  # reported by the motors' own check
            bad(
                where,
                f"{name!r} ({what}) is also the name of {other_where} ({other_what}); "
                "expected a name no other device of the robot has",
            )
            continue
        seen[name] = (what, where)
    return problems


def unserved_cameras(manifest: Manifest) -> list[ModelProblem]:
    """Warnings for the cameras after the first: the robot API serves one camera per robot."""
    first = manifest.cameras[0].name if manifest.cameras else ""
    return [
        ModelProblem(
            source=str(manifest.path),
            where=f"/cameras/{k}",
            reason=f"camera {camera.name!r} is not served: the robot API renders one camera "
            f"per robot ({first!r}, /cameras/0); it still counts for the rule book",
            severity="warning",
        )
        for k, camera in enumerate(manifest.cameras)
        if k > 0
    ]
