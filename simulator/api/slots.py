"""What the pieces of the robot API server share: a robot's slot (its endpoint, session, quota,
counters and current client), the server's settings and errors.

The server (:mod:`simulator.api.server`) is put together from :class:`~simulator.api.ports.Ports`
(the sockets: listening, accepting, reading, writing, dropping), :class:`~simulator.api.intake.
Intake` (the clients' requests applied to the world) and :class:`~simulator.api.outbox.Outbox`
(the step's measurements framed, counted and queued); each works on the same slots.
"""

from __future__ import annotations

import socket
from collections import deque
from concurrent.futures import Future
from dataclasses import dataclass, field

from contracts.robot_api import messages_pb2 as pb
from simulator.api.connection import Connection
from simulator.api.endpoints import PlayerEndpoint
from simulator.api.fastreq import Notice, PositionTargets
from simulator.api.measurement import Measurement
from simulator.api.quota import NetworkQuota
from simulator.api.session import RobotSession
from simulator.api.stats import RobotStats
from simulator.errors import ApiError

Request = pb.ActuatorRequests | PositionTargets | Notice


class IoThreadFailed(ApiError):
    """The thread doing the clients' socket I/O stopped on an unexpected error."""

    def __init__(self, failure: Exception) -> None:
        self.failure = failure
        super().__init__(
            f"the robot API I/O thread failed ({failure!r}): no robot would receive"
            " measurements any more, so the match stops here"
        )


class PortUnavailable(ApiError):
    def __init__(self, *, host: str, port: int, reason: str) -> None:
        self.host = host
        self.port = port
        self.reason = reason
        super().__init__(f"cannot listen on {host}:{port}: {reason}")


@dataclass(frozen=True, slots=True, kw_only=True)
class LockstepSettings:
    deadline_s: float
    time_bank_s: float
    # pipelined lockstep: the clients' socket I/O runs on the I/O thread, while the physics
    # runs; plain lockstep keeps it on the step thread (fewer wake-ups in the critical path)
    pipelined: bool = False


@dataclass(slots=True)
class Pending:
    """A measurement waiting for camera images (and the ones queued behind it)."""

    measurement: Measurement
    missing: int


@dataclass(slots=True, eq=False)
class RobotSlot:
    endpoint: PlayerEndpoint
    session: RobotSession
    quota: NetworkQuota
    stats: RobotStats
    listener: socket.socket | None = None
    conn: Connection | None = None
    checking: tuple[socket.socket, str, Future[bool]] | None = None
    pending: deque[Pending] = field(default_factory=deque)
    mask: int = 0
