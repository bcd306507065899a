"""The per-step batch over all robots gives the bytes and targets of the robot-by-robot path."""

from __future__ import annotations

import math

import numpy as np

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api.batch import StepBatch
from simulator.api.fastreq import PositionTargets
from simulator.api.framing import HEADER
from simulator.api.measurement import DuePlan, Measurement, header_bytes
from simulator.api.session import RobotSession
from simulator.world import FORCE_SENSORS, MOTOR_NAMES, RobotPlacement, World

ROBOTS = [RobotId(TeamColor.RED, 1), RobotId(TeamColor.RED, 2), RobotId(TeamColor.BLUE, 1)]


def _world() -> World:
    placements = [
        RobotPlacement(id=r, model="kid-default", x_m=-1.0 + i, y_m=0.5 * i, yaw_rad=0.3 * i)
        for i, r in enumerate(ROBOTS)
    ]
    return World.create(field_class="kid", robots=placements, seed=3)


def _sessions(world: World) -> list[RobotSession]:
    return [
        RobotSession(robot=r, world=world, rendering_quota_mb_s=100.0, clock_ms=lambda: 1234)
        for r in ROBOTS
    ]


def _enable(session: RobotSession, periods: dict[str, int]) -> None:
    request = pb.ActuatorRequests()
    for name, period in periods.items():
        request.sensor_time_steps.add(name=name, timeStep=period)
    session.apply_all([request], step_time_ms=8)


def test_batched_measurements_are_the_robot_by_robot_ones() -> None:
    world = _world()
    sessions = _sessions(world)
    # three different sensor sets, one at two periods, force sensors on another
    _enable(sessions[0], {f"{m}S": 8 for m in MOTOR_NAMES} | {"Accelerometer": 8, "Gyro": 8})
    _enable(sessions[1], {"NeckS": 8, "Gyro": 16, **dict.fromkeys(FORCE_SENSORS, 8)})
    _enable(sessions[2], {"HeadS": 8, "AnkleLS": 8, "Accelerometer": 8})
    batch = StepBatch(world)
    assert StepBatch.supports(world)
    plain = with_message = 0
    for step in range(2, 40):
        world.step()
        if step == 20:
            sessions[2].warn("a warning in this step only")
        time_ms = world.sim_time_ms
        items = []
        for session in sessions:
            measurement, plan = session.begin_measure(time_ms, 1234)
            if plan is not None:
                items.append((measurement, plan, session))
        if not items:  # the step that enabled the sensors reports none of them
            continue
        head = header_bytes(time_ms, 1234)
        batch.encode([(m, p) for m, p, _ in items], head)
        for measurement, plan, session in items:
            expected = session.encode(plan)
            assert measurement.sensors == expected
            if measurement.plain:
                plain += 1
                size = len(head) + len(expected)
                assert measurement.frame == HEADER.pack(size) + head + expected
                parsed = pb.SensorMeasurements()
                parsed.ParseFromString(measurement.frame[HEADER.size :])
                assert parsed.time == time_ms and parsed.real_time == 1234
            else:
                with_message += 1
                assert measurement.frame is None  # its head has the message: framed later
    assert plain > 60 and with_message == 1


def test_batched_targets_are_the_robot_by_robot_ones() -> None:
    batched, single = _world(), _world()
    names = tuple(MOTOR_NAMES)
    b_sessions, s_sessions = _sessions(batched), _sessions(single)
    batch = StepBatch(batched)
    rng = np.random.default_rng(5)
    for step in range(30):
        targets = []
        for b_session, s_session in zip(b_sessions, s_sessions, strict=True):
            values = rng.uniform(-4.0, 4.0, len(names))  # beyond the joint limits: clamped
            if step == 10:
                values[3] = math.nan  # ignored, the others still apply
            request = PositionTargets(names, values, finite=bool(np.isfinite(values).all()))
            b_session.update_limp()
            s_session.update_limp()
            usual = b_session.take_targets([request])
            if usual is None:
                b_session.apply_all([request], step_time_ms=8)
            else:
                targets.append(usual)
            s_session.apply_all([request], step_time_ms=8)
        if targets:
            batch.set_targets(targets)
        # the first request's names are checked, the second is held: batched from the third,
        # but for targets with a NaN (filtered robot by robot)
        assert len(targets) == (0 if step < 2 or step == 10 else len(ROBOTS))
        np.testing.assert_array_equal(batched.motors.target, single.motors.target)
        batched.step()
        single.step()
    np.testing.assert_array_equal(batched.data.qpos, single.data.qpos)


def test_a_limp_or_removed_robot_is_not_batched() -> None:
    world = _world()
    (session, *_) = _sessions(world)
    names = tuple(MOTOR_NAMES)
    request = PositionTargets(names, np.zeros(len(names)), finite=True)
    session.update_limp()
    for _ in range(2):  # the names are checked, then held
        assert session.take_targets([request]) is None
        session.apply_all([request], step_time_ms=8)
    assert session.take_targets([request]) is not None
    world.limp[0] = True
    session.update_limp()
    assert session.take_targets([request]) is None
    world.limp[0] = False
    world.removed[0] = True
    session.update_limp()
    assert session.take_targets([request]) is None


def test_gathered_values_are_written_as_read_even_after_the_world_moves_on() -> None:
    """With the I/O thread the values are read on the step thread and written as wire bytes
    there later: the bytes are those of the step they were read in, and two gathered steps
    written in any order do not share a buffer."""
    world = _world()
    sessions = _sessions(world)
    for session in sessions:
        _enable(session, {f"{m}S": 8 for m in MOTOR_NAMES} | {"Gyro": 8})
    batch = StepBatch(world)

    def measured() -> tuple[list[tuple[Measurement, DuePlan]], bytes, list[bytes]]:
        while True:  # (the step that enabled them reports none)
            world.step()
            time_ms = world.sim_time_ms
            due = [session.begin_measure(time_ms, 1234) for session in sessions]
            items = [(m, plan) for m, plan in due if plan is not None]
            if len(items) == len(sessions):
                break
        head = header_bytes(time_ms, 1234)
        expected = [s.encode(plan) for s, (_, plan) in zip(sessions, items, strict=True)]
        return items, head, expected

    first_items, first_head, first_expected = measured()
    first = batch.gather(first_items, first_head)
    second_items, second_head, second_expected = measured()  # the world has moved on
    second = batch.gather(second_items, second_head)
    assert first_expected != second_expected
    second.write()
    first.write()
    for items, head, expected in ((first_items, first_head, first_expected),
                                  (second_items, second_head, second_expected)):  # fmt: skip
        for (measurement, _), sensors in zip(items, expected, strict=True):
            assert measurement.frame == HEADER.pack(len(head) + len(sensors)) + head + sensors
