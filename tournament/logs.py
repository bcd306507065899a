"""The truth about a match's log sets: one state per team (and the public set) in the ledger.

A set is ``pending`` from the moment the match is played until a delivery was tried, then
``delivered`` or ``failed`` with its typed cause (``DeliveryError.kind`` and reason). A failed
set is tried again every ``timing.retry_s`` up to ``timing.delivery_attempts`` times; while a
retry is due it is ``retrying``. A team whose match left no log files has ``none``, and a set
that left the store before a retry (delivered by ``hlvs logs deliver`` or pruned) ``gone``.
A match is DELIVERED only when every set was delivered (or there was none).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

from contracts import JSONObject, from_data, to_data

LogState = Literal["pending", "delivered", "failed", "retrying", "none", "gone"]
DONE: frozenset[str] = frozenset({"delivered", "none"})


@dataclass(frozen=True, slots=True, kw_only=True)
class TeamLogs:
    """One team's (or the public) log set of one match; in the ledger as JSON (its fields, read
    by :func:`contracts.codec.from_data`: earlier ledgers may lack the keys with a default)."""

    team: str
    state: LogState
    cause: str = ""  # "<kind>: <reason>" of the last failure
    target: str = ""
    attempts: int = 0

    def as_dict(self) -> JSONObject:
        data: JSONObject = to_data(self)
        return data

    @classmethod
    def from_dict(cls, data: object, *, source: str = "ledger") -> TeamLogs:
        """A set read back; :class:`~contracts.errors.ContractError` names a field that does
        not fit."""
        return from_data(cls, data, source=source)

    def describe(self) -> str:
        """``ants delivered``, ``bees failed after 3 attempts (unreachable: ...)``."""
        text = f"{self.team} {self.state}"
        if self.attempts > 1:
            text += f" after {self.attempts} attempts"
        if self.cause and self.state not in DONE:
            text += f" ({self.cause})"
        return text


def all_done(logs: list[TeamLogs]) -> bool:
    return all(entry.state in DONE for entry in logs)


def summary(logs: list[TeamLogs]) -> str:
    """One line for the ledger's note and the run log."""
    if not logs:
        return "logs: none"
    return "logs: " + "; ".join(entry.describe() for entry in logs)


def with_retry(logs: list[TeamLogs], *, retry: bool) -> list[TeamLogs]:
    """Failed sets become ``retrying`` when another attempt is planned."""
    if not retry:
        return logs
    return [
        TeamLogs(team=e.team, state="retrying", cause=e.cause, target=e.target,
                 attempts=e.attempts) if e.state == "failed" else e
        for e in logs
    ]
