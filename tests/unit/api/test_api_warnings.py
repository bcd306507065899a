"""Warnings repeat on every request that earns one, as the league's server sends them
(``warn``, controllers/player/player.cpp:213, called per request in ``processBuffer``), bounded
per measurement so that a client cannot flood the server or itself."""

from __future__ import annotations

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import FakeDeviceWorld, RobotSession
from simulator.api.fastreq import Notice
from simulator.api.session import MAX_WARNING_CHARS, MAX_WARNINGS

RED1 = RobotId(TeamColor.RED, 1)
BAD = [
    'Motor "Tail" not found, position command ignored.',
    'Time step for "Gyro" should be a multiple of 8, ignoring 12 value.',
    'Device "Lidar" not found, time step command, ignored.',
]


def _session() -> RobotSession:
    return RobotSession(
        robot=RED1, world=FakeDeviceWorld([RED1]), rendering_quota_mb_s=87.5, clock_ms=lambda: 7
    )


def _bad_request(tail: str = "Tail") -> pb.ActuatorRequests:
    request = pb.ActuatorRequests()
    request.motor_positions.add(name=tail, position=1.0)
    request.sensor_time_steps.add(name="Gyro", timeStep=12)
    request.sensor_time_steps.add(name="Lidar", timeStep=8)
    return request


def _texts(session: RobotSession, t: int) -> list[str]:
    return [m.text for m in session.measure(t).parsed().messages]


def test_a_bad_request_is_warned_about_every_time_it_is_sent() -> None:
    session = _session()
    texts: list[list[str]] = []
    for t in range(8, 88, 8):  # the same bad request at every step
        session.apply(_bad_request(), step_time_ms=t)
        texts.append(_texts(session, t))
    assert texts == [BAD] * 10
    for _ in range(2):  # twice in one step: twice in its measurement
        session.apply(_bad_request(), step_time_ms=88)
    assert _texts(session, 88) == BAD * 2
    assert _texts(session, 96) == []  # a step without a bad request: nothing


def test_warnings_per_measurement_are_bounded() -> None:
    session = _session()
    for k in range(100):
        session.apply(_bad_request(f"Tail{k}"), step_time_ms=8)
    texts = _texts(session, 8)
    assert len(texts) == MAX_WARNINGS + 1
    assert texts[0] == 'Motor "Tail0" not found, position command ignored.'
    assert texts[-1] == (
        f"{300 - MAX_WARNINGS} more warnings since the last measurement not sent"
        f" (at most {MAX_WARNINGS} per measurement)."
    )
    session.apply(_bad_request(), step_time_ms=16)  # the next measurement starts afresh
    assert _texts(session, 16) == BAD


def test_a_long_device_name_is_cut_in_the_middle_of_its_warning() -> None:
    session = _session()
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="x" * 200_000, position=1.0)
    session.apply(request, step_time_ms=8)
    (text,) = _texts(session, 8)
    assert len(text) <= MAX_WARNING_CHARS
    assert text.startswith('Motor "xxx') and text.endswith('" not found, position command ignored.')


def test_a_notice_of_the_reader_is_sent_as_a_warning() -> None:
    session = _session()
    session.apply_all([Notice("ActuatorRequests of 300000 bytes is above the limit")],
                      step_time_ms=8)  # fmt: skip
    assert _texts(session, 8) == ["ActuatorRequests of 300000 bytes is above the limit"]


def test_errors_are_not_bounded() -> None:
    session = _session()
    for _ in range(MAX_WARNINGS):
        session.warn("a warning")
    for t in (8, 16):
        session.warn("350 MB/s quota exceeded.", kind=pb.Message.ERROR_MESSAGE)
        messages = session.measure(t).parsed().messages
        assert messages[-1].text == "350 MB/s quota exceeded."
        assert messages[-1].message_type == pb.Message.ERROR_MESSAGE
