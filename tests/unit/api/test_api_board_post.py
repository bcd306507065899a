"""A connection on the server's target board puts a usual request's targets straight onto its
span (no request object made); anything else takes the usual way, so the board sees what it
would have seen."""

from __future__ import annotations

import math
import socket
from collections.abc import Iterator, Sequence

import pytest

from contracts.robot_api import messages_pb2 as pb
from simulator.api.connection import Connection, Request
from simulator.api.fastreq import PositionTargets
from simulator.api.framing import encode_frame

from .conftest import connection_pair, read_sent

NAMES = ("Neck", "Head", "AnkleL")


class _Span:
    """A board span that records what reaches it and how."""

    def __init__(self) -> None:
        self.names: tuple[str, ...] | None = None
        self.values: list[list[float]] = []
        self.posted: list[Request] = []

    def post_values(self, names: tuple[str, ...], values: Sequence[float]) -> bool:
        if names is not self.names:
            return False
        self.values.append(list(values))
        return True

    def post(self, decoded: Sequence[Request], queue: list[Request]) -> None:
        self.posted.extend(decoded)


def _frame(values: Sequence[float], names: Sequence[str] = NAMES) -> bytes:
    request = pb.ActuatorRequests()
    for name, value in zip(names, values, strict=True):
        request.motor_positions.add(name=name, position=value)
    return encode_frame(request.SerializeToString())


@pytest.fixture
def pair() -> Iterator[tuple[Connection, socket.socket]]:
    with connection_pair() as both:
        yield both


def test_a_usual_request_goes_straight_onto_the_span(
    pair: tuple[Connection, socket.socket],
) -> None:
    conn, theirs = pair
    span = _Span()
    assert read_sent(conn, theirs, _frame([0.1, 0.2, 0.3])) == 1  # the first: protobuf, a template
    assert conn.requests and conn.template is not None
    conn.requests.clear()
    span.names = conn.template.names
    conn.board = span
    assert read_sent(conn, theirs, _frame([0.4, -0.5, 0.6])) == 1
    assert span.values == [[0.4, -0.5, 0.6]] and not span.posted and not conn.requests
    assert conn.answered and conn.stats.messages_in == 2


@pytest.mark.parametrize("values", [[0.4, math.nan, 0.6], [0.4, 0.5, math.inf]])
def test_a_request_not_finite_takes_the_usual_way(
    pair: tuple[Connection, socket.socket], values: list[float],
) -> None:
    conn, theirs = pair
    read_sent(conn, theirs, _frame([0.1, 0.2, 0.3]))
    conn.requests.clear()
    assert conn.template is not None
    span = _Span()
    span.names = conn.template.names
    conn.board = span
    assert read_sent(conn, theirs, _frame(values)) == 1
    assert not span.values
    (posted,) = span.posted
    assert isinstance(posted, PositionTargets) and not posted.finite


def test_other_names_or_a_queue_take_the_usual_way(
    pair: tuple[Connection, socket.socket],
) -> None:
    conn, theirs = pair
    read_sent(conn, theirs, _frame([0.1, 0.2, 0.3]))
    conn.requests.clear()
    span = _Span()
    span.names = ("Neck", "Head", "AnkleL")  # equal, but not the session's own list
    conn.board = span
    read_sent(conn, theirs, _frame([0.4, 0.5, 0.6]))
    assert not span.values and len(span.posted) == 1
    assert conn.template is not None
    span.names = conn.template.names
    conn.requests.append(PositionTargets(NAMES, [0.0, 0.0, 0.0]))  # something queued first
    read_sent(conn, theirs, _frame([0.7, 0.8, 0.9]))
    assert not span.values and len(span.posted) == 2  # behind what is queued, in order
