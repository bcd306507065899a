"""Position targets decoded without protobuf agree with protobuf on every frame they accept."""

from __future__ import annotations

import math

from hypothesis import given
from hypothesis import strategies as st

from contracts.robot_api import messages_pb2 as pb
from simulator.api.fastreq import PositionTemplate, scan_positions

NAMES = ("Neck", "Head", "ShoulderL", "AnkleR", "Ü-motor")


def _request(pairs: list[tuple[str, float]]) -> bytes:
    request = pb.ActuatorRequests()
    for name, position in pairs:
        request.motor_positions.add(name=name, position=position)
    return bytes(request.SerializeToString())


def _template() -> PositionTemplate:
    template = scan_positions(_request([(n, 0.25 + i) for i, n in enumerate(NAMES)]))
    assert template is not None
    return template


def test_same_names_other_values_match_and_decode() -> None:
    template = _template()
    assert template.names == NAMES
    values = [-1.5, 1e-300, math.inf, 3.0, -0.125]
    targets = template.match(_request(list(zip(NAMES, values, strict=True))))
    assert targets is not None
    assert targets.names == NAMES and list(targets.values) == values
    assert not targets.finite  # the infinity: the step thread checks these robot by robot


def test_finite_tells_whether_every_value_is_a_number() -> None:
    template = _template()
    for values, finite in (
        ([-1.5, 1e-300, 2.0, 3.0, -0.125], True),
        ([-1.5, math.nan, 2.0, 3.0, -0.125], False),
        ([-1.5, 1.0, 2.0, -math.inf, -0.125], False),
        ([1e308, 1e308, 2.0, 3.0, -0.125], False),  # the sum overflows: checked as if not
    ):
        targets = template.match(_request(list(zip(NAMES, values, strict=True))))
        assert targets is not None and targets.finite is finite, values


def test_other_layouts_do_not_match() -> None:
    template = _template()
    zero = _request([(n, 0.0 if i == 2 else 1.0) for i, n in enumerate(NAMES)])  # left out
    swapped = _request([(n, 1.0) for n in reversed(NAMES)])
    other = pb.ActuatorRequests()
    other.ParseFromString(_request([(n, 1.0) for n in NAMES]))
    other.sensor_time_steps.add(name="Gyro", timeStep=8)
    for frame in (zero, swapped, bytes(other.SerializeToString()), b"", b"\x0a"):
        assert template.match(frame) is None
    assert scan_positions(bytes(other.SerializeToString())) is None
    assert scan_positions(zero) is None  # the item without a position cannot be a template


@given(st.lists(st.tuples(st.integers(0, 200), st.integers(0, 255)), max_size=4))
def test_a_changed_byte_either_misses_or_parses_to_the_same_targets(
    changes: list[tuple[int, int]],
) -> None:
    template = _template()
    frame = bytearray(_request([(n, 2.0) for n in NAMES]))
    for at, value in changes:
        frame[at % len(frame)] = value
    targets = template.match(bytes(frame))
    if targets is None:
        return
    request = pb.ActuatorRequests()
    request.ParseFromString(bytes(frame))
    assert tuple(m.name for m in request.motor_positions) == targets.names
    parsed = [m.position for m in request.motor_positions]
    assert all(
        a == b or (math.isnan(a) and math.isnan(b))
        for a, b in zip(parsed, targets.values, strict=True)
    )


@given(st.binary(max_size=200))
def test_scan_accepts_only_frames_protobuf_reads_as_the_same_targets(frame: bytes) -> None:
    template = scan_positions(frame)
    if template is None:
        return
    targets = template.match(frame)
    assert targets is not None
    request = pb.ActuatorRequests()
    request.ParseFromString(frame)
    assert len(request.ListFields()) == 1
    assert tuple(m.name for m in request.motor_positions) == targets.names
    parsed = [m.position for m in request.motor_positions]
    assert all(
        a == b or (math.isnan(a) and math.isnan(b))
        for a, b in zip(parsed, targets.values, strict=True)
    )


@given(st.lists(st.tuples(st.sampled_from(NAMES), st.floats()), min_size=1, max_size=8))
def test_scan_of_encoded_requests(pairs: list[tuple[str, float]]) -> None:
    frame = _request(pairs)
    template = scan_positions(frame)
    # proto3 leaves +0.0 out (protobuf's way); -0.0 has a non-zero bit pattern and is written
    if any(value == 0.0 and math.copysign(1.0, value) > 0 for _, value in pairs):
        assert template is None
        return
    assert template is not None
    targets = template.match(frame)
    assert targets is not None and targets.names == tuple(n for n, _ in pairs)


def test_session_applies_decoded_targets_like_requests() -> None:
    from contracts.ids import RobotId, TeamColor
    from simulator.api import FakeDeviceWorld, RobotSession
    from simulator.api.fastreq import PositionTargets

    red1 = RobotId(TeamColor.RED, 1)
    world = FakeDeviceWorld([red1])
    session = RobotSession(robot=red1, world=world, rendering_quota_mb_s=1.0, clock_ms=lambda: 1)
    session.update_limp()
    session.apply_all([PositionTargets(("Neck", "Tail", "Neck"), (0.1, 0.2, 0.3))], step_time_ms=8)
    assert world.calls == [("position", red1, "Neck", (0.3,))]  # the later target wins
    assert [m.text for m in session.measure(8).parsed().messages] == [
        'Motor "Tail" not found, position command ignored.'
    ]
    world.calls.clear()
    world.limp.add(red1)
    session.update_limp()
    session.apply_all([PositionTargets(("Neck", "Head"), (0.5, 0.6))], step_time_ms=16)
    session.apply_all([PositionTargets(("Neck", "Head"), (0.7, 0.8))], step_time_ms=24)
    assert world.calls == []
    world.limp.discard(red1)
    session.update_limp()
    assert sorted(world.calls) == [
        ("position", red1, "Head", (0.8,)),
        ("position", red1, "Neck", (0.7,)),
    ]


def test_finite_values_are_the_values_match_takes_when_all_are_finite() -> None:
    template = _template()
    values = [-1.5, 1e-300, 2.0, 3.0, -0.125]
    frame = _request(list(zip(NAMES, values, strict=True)))
    targets = template.match(frame)
    assert targets is not None
    assert template.finite_values(frame) == tuple(values) == tuple(targets.values)
    for bad in ([-1.5, math.nan, 2.0, 3.0, -0.125], [1e308, 1e308, 2.0, 3.0, -0.125]):
        assert template.finite_values(_request(list(zip(NAMES, bad, strict=True)))) is None
    assert template.finite_values(_request([(n, 1.0) for n in reversed(NAMES)])) is None
