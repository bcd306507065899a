"""The cached wire layout of measurements and the batch world path of the session."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import FakeDeviceWorld, RobotSession
from simulator.api.devices import KID_MOTORS
from simulator.api.encode import (
    ACCELEROMETERS,
    FORCES,
    GYROS,
    POSITION_SENSORS,
    SensorEncoder,
    SensorLayout,
)

RED1 = RobotId(TeamColor.RED, 1)


def test_layout_bytes_equal_the_per_sensor_encoder_and_parse() -> None:
    entries = [
        (ACCELEROMETERS, "Accelerometer", 3),
        (FORCES, "llb", 1),
        (GYROS, "Gyro", 3),
        (POSITION_SENSORS, "NeckS", 1),
        (POSITION_SENSORS, "x" * 200, 1),  # a name longer than one varint byte
    ]
    values = [0.1, -0.2, 9.81, 4.5, 0.0, 1e-300, -3.0, 0.25, -1.5]
    encoder = SensorEncoder()
    expected = (
        encoder.vector(ACCELEROMETERS, "Accelerometer", 0.1, -0.2, 9.81)
        + encoder.scalar(FORCES, "llb", 4.5)
        + encoder.vector(GYROS, "Gyro", 0.0, 1e-300, -3.0)
        + encoder.scalar(POSITION_SENSORS, "NeckS", 0.25)
        + encoder.scalar(POSITION_SENSORS, "x" * 200, -1.5)
    )
    layout = SensorLayout(entries)
    assert layout.values == len(values)
    assert layout.encode(values) == expected
    assert layout.encode(np.array(values)) == expected
    msg = pb.SensorMeasurements()
    msg.ParseFromString(layout.encode(values))
    assert (msg.gyros[0].value.Y, msg.position_sensors[1].value) == (1e-300, -1.5)
    assert msg.position_sensors[1].name == "x" * 200


class BatchFakeWorld(FakeDeviceWorld):
    """The fake world with the batch calls of simulator.world.World."""

    def set_motor_positions(
        self, robot: RobotId, names: Sequence[str], rads: Sequence[float]
    ) -> None:
        self.calls.append(("positions", robot, ",".join(names), tuple(rads)))
        self.targets[robot].update(zip(names, rads, strict=True))

    def read_sensors(self, robot: RobotId, names: Sequence[str]) -> list[float]:
        values: list[float] = []
        for name in names:
            if name == "Accelerometer":
                values.extend(self.read_accelerometer(robot))
            elif name == "Gyro":
                values.extend(self.read_gyro(robot))
            elif name.endswith("S"):
                values.append(self.read_position(robot, name))
            else:
                values.append(self.read_force(robot, name))
        return values


def _run(world: FakeDeviceWorld) -> list[bytes]:
    session = RobotSession(robot=RED1, world=world, rendering_quota_mb_s=87.5, clock_ms=lambda: 7)
    enable = pb.ActuatorRequests()
    for name, period in {"Gyro": 16, "NeckS": 8, "llb": 24, "HeadS": 8, "Accelerometer": 8}.items():
        enable.sensor_time_steps.add(name=name, timeStep=period)
    session.apply(enable, step_time_ms=8)
    payloads = []
    for t in range(8, 80, 8):
        request = pb.ActuatorRequests()
        for i, motor in enumerate(KID_MOTORS):
            request.motor_positions.add(name=motor, position=0.1 * math.sin(t + i))
        request.motor_positions.add(name="Neck", position=0.5)  # the later target wins
        request.motor_positions.add(name="Tail", position=0.5)  # warned, ignored
        session.apply(request, step_time_ms=t + 8)
        world.step()
        payloads.append(session.measure(t + 8).payload())
    return payloads


def test_batch_world_gives_the_same_measurements_as_single_calls() -> None:
    single, batch = FakeDeviceWorld([RED1]), BatchFakeWorld([RED1])
    assert _run(single) == _run(batch)
    assert batch.positions[RED1]["Neck"] == 0.5
    assert {c[0] for c in batch.calls} == {"positions"}
    payloads = _run(BatchFakeWorld([RED1]))
    first = pb.SensorMeasurements()
    first.ParseFromString(payloads[0])
    assert [m.text for m in first.messages] == ['Motor "Tail" not found, position command ignored.']
    msg = pb.SensorMeasurements()
    msg.ParseFromString(payloads[2])  # t = 32: every sensor but the gyro
    assert [s.name for s in msg.position_sensors] == ["NeckS", "HeadS"]
    assert msg.position_sensors[0].value == 0.5
    assert (len(msg.accelerometers), len(msg.gyros), len(msg.forces)) == (1, 0, 1)
    # the bad target is in every request: warned about in every measurement
    assert [m.text for m in msg.messages] == ['Motor "Tail" not found, position command ignored.']


def test_sensors_of_several_periods_keep_their_enabling_order() -> None:
    world = FakeDeviceWorld([RED1])
    session = RobotSession(robot=RED1, world=world, rendering_quota_mb_s=87.5, clock_ms=lambda: 7)
    enable = pb.ActuatorRequests()
    for name, period in {"NeckS": 8, "HeadS": 16, "ShoulderLS": 8, "Camera": 32}.items():
        enable.sensor_time_steps.add(name=name, timeStep=period)
    session.apply(enable, step_time_ms=8)
    seen = {}
    for t in range(8, 48, 8):
        measurement = session.measure(t)
        msg = measurement.parsed()
        seen[t] = ([s.name for s in msg.position_sensors], [j.time_ms for j in measurement.jobs])
    assert seen[8] == ([], [])  # the enabling step
    assert seen[16] == (["NeckS", "ShoulderLS"], [])
    assert seen[24] == (["NeckS", "HeadS", "ShoulderLS"], [])
    assert seen[40] == (["NeckS", "HeadS", "ShoulderLS"], [40])
    session.apply(
        pb.ActuatorRequests(sensor_time_steps=[{"name": "NeckS", "timeStep": 0}]), step_time_ms=48
    )
    assert [s.name for s in session.measure(48).parsed().position_sensors] == ["ShoulderLS"]
