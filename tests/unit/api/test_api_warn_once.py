"""A request the robot API server warns about is warned about once, not at every step."""

from __future__ import annotations

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import FakeDeviceWorld, RobotSession

RED1 = RobotId(TeamColor.RED, 1)


def _bad_request(tail: str = "Tail") -> pb.ActuatorRequests:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name=tail, position=1.0)
    request.sensor_time_steps.add(name="Gyro", timeStep=12)
    request.sensor_time_steps.add(name="Lidar", timeStep=8)
    return request


def test_each_distinct_warning_goes_out_once() -> None:
    session = RobotSession(
        robot=RED1, world=FakeDeviceWorld([RED1]), rendering_quota_mb_s=87.5, clock_ms=lambda: 7
    )
    texts: list[list[str]] = []
    for t in range(8, 88, 8):  # the same bad request at every step
        session.apply(_bad_request(), step_time_ms=t)
        texts.append([m.text for m in session.measure(t).parsed().messages])
    assert texts[0] == [
        'Motor "Tail" not found, position command ignored.',
        'Time step for "Gyro" should be a multiple of 8, ignoring 12 value.',
        'Device "Lidar" not found, time step command, ignored.',
    ]
    assert all(step == [] for step in texts[1:]), texts
    session.apply(_bad_request("Wing"), step_time_ms=88)  # a different bad request is news
    assert [m.text for m in session.measure(88).parsed().messages] == [
        'Motor "Wing" not found, position command ignored.'
    ]


def test_errors_are_not_deduplicated() -> None:
    session = RobotSession(
        robot=RED1, world=FakeDeviceWorld([RED1]), rendering_quota_mb_s=87.5, clock_ms=lambda: 7
    )
    for t in (8, 16):
        session.warn("350 MB/s quota exceeded.", kind=pb.Message.ERROR_MESSAGE)
        messages = session.measure(t).parsed().messages
        assert [m.text for m in messages] == ["350 MB/s quota exceeded."]
