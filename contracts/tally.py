"""A team's record over its matches: played, won, drawn, lost, goals for and against. One
counter for every table of results: the round robin's standings
(:class:`tournament.Standing`, which adds the points and the tie-break) and the service's
ladder (``service.ratings.TeamRating``, which adds the rating)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

Outcome = Literal["won", "drawn", "lost"]


@dataclass(slots=True)
class Tally:
    team: str
    played: int = 0
    won: int = 0
    drawn: int = 0
    lost: int = 0
    goals_for: int = 0
    goals_against: int = 0

    @property
    def goal_difference(self) -> int:
        return self.goals_for - self.goals_against

    def count(self, goals_for: int, goals_against: int, outcome: Outcome | None = None) -> None:
        """One more match with these goals; ``outcome`` when the goals do not decide it (a
        forfeit is recorded 0:0 and won by one side), else the goals do."""
        if outcome is None:
            outcome = "won" if goals_for > goals_against else \
                "lost" if goals_for < goals_against else "drawn"
        self.played += 1
        self.goals_for += goals_for
        self.goals_against += goals_against
        if outcome == "won":
            self.won += 1
        elif outcome == "lost":
            self.lost += 1
        else:
            self.drawn += 1


__all__ = ["Outcome", "Tally"]
