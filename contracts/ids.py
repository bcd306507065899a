"""Who is who in a match: team colours and robot ids, the same in every process."""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class TeamColor(str, Enum):  # noqa: UP042 (str() stays the qualified name)
    RED = "red"
    BLUE = "blue"

    @property
    def opponent(self) -> TeamColor:
        return TeamColor.BLUE if self is TeamColor.RED else TeamColor.RED


COLORS = (TeamColor.RED, TeamColor.BLUE)


@dataclass(frozen=True, slots=True)
class RobotId:
    team: TeamColor
    number: int  # 1-based player number

    def __str__(self) -> str:
        return f"{self.team.value} player {self.number}"

    @property
    def key(self) -> str:
        """``red-1``: the robot's name in file names, statistics and container names."""
        return f"{self.team.value}-{self.number}"


__all__ = ["COLORS", "RobotId", "TeamColor"]
