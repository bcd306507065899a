"""Messages from robots are attributed by their sender's address, never by their content.

Every robot has a known address (its team network address, ``robot_addresses`` of the spec).
A message that claims to come from a robot other than the one(s) at its sender's address is a
spoofing attempt: it is not acted upon, and it is recorded here with the sender. The GameController
return port, the team mirror and the robot API ports share one :class:`SpoofingLog`; the referee
writes the new attempts into its logs and the simulator puts :meth:`SpoofingLog.records` into
``sim_result.json`` (``spoofing``).
"""

from __future__ import annotations

import threading
from collections.abc import Mapping

from contracts import RobotId, SpoofingAttempt

MAX_RECORDS = 256  # distinct (channel, sender, claimed, message) kept; the rest only counted


def robot_key(robot: RobotId) -> str:
    """``red-1``: the robot key used in results."""
    return f"{robot.team.value}-{robot.number}"


class Senders:
    """Which robots are at which address (several robots may share one, as on loopback)."""

    def __init__(self, addresses: Mapping[RobotId, str]) -> None:
        self._robots: dict[str, frozenset[RobotId]] = {}
        for robot, address in addresses.items():
            if address:
                self._robots[address] = self._robots.get(address, frozenset()) | {robot}

    @property
    def known(self) -> bool:
        """False when no address is known: messages can only be taken at their word."""
        return bool(self._robots)

    def robots_at(self, address: str) -> frozenset[RobotId]:
        return self._robots.get(address, frozenset())

    def label(self, address: str) -> str | None:
        robots = sorted(robot_key(r) for r in self.robots_at(address))
        return ",".join(robots) if robots else None

    def may_speak_for(self, address: str, robot: RobotId) -> bool:
        return not self.known or robot in self.robots_at(address)


class SpoofingLog:
    """Thread-safe record of spoofing attempts; :meth:`take_new` hands each new kind once."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._counts: dict[tuple[str, str, str | None, str | None, str], int] = {}
        self._new: list[SpoofingAttempt] = []
        self._overflow = 0

    def record(self, *, channel: str, sender: str, sender_robot: str | None,
               claimed: str | None, message: str) -> None:
        key = (channel, sender, sender_robot, claimed, message)
        with self._lock:
            if key in self._counts:
                self._counts[key] += 1
                return
            if len(self._counts) >= MAX_RECORDS:
                self._overflow += 1
                return
            self._counts[key] = 1
            self._new.append(SpoofingAttempt(
                channel=channel, sender=sender, sender_robot=sender_robot, claimed=claimed,
                message=message,
            ))

    def take_new(self) -> list[SpoofingAttempt]:
        with self._lock:
            new, self._new = self._new, []
        return new

    @property
    def total(self) -> int:
        with self._lock:
            return sum(self._counts.values()) + self._overflow

    def records(self) -> list[SpoofingAttempt]:
        with self._lock:
            items = list(self._counts.items())
        return [
            SpoofingAttempt(channel=c, sender=s, sender_robot=r, claimed=cl, message=m, count=n)
            for (c, s, r, cl, m), n in sorted(items, key=lambda kv: (kv[0][0], kv[0][1],
                                                                     str(kv[0][3]), kv[0][4]))
        ]

    def to_json(self) -> dict[str, object]:
        """``{"total": n, "attempts": [...]}`` for ``sim_result.json``."""
        return {"total": self.total, "attempts": [a.to_json() for a in self.records()]}


__all__ = ["MAX_RECORDS", "Senders", "SpoofingAttempt", "SpoofingLog", "robot_key"]
