"""Standings of the round-robin matches: 3 points a win, 1 a draw; then goal difference, goals."""

from __future__ import annotations

from dataclasses import dataclass

from tournament.state import MatchRow, ScheduledMatchState

COUNTED = (
    ScheduledMatchState.PLAYED,
    ScheduledMatchState.DELIVERING,
    ScheduledMatchState.DELIVERED,
    ScheduledMatchState.LOGS_PENDING,
)


@dataclass(slots=True)
class Standing:
    team: str
    played: int = 0
    won: int = 0
    drawn: int = 0
    lost: int = 0
    goals_for: int = 0
    goals_against: int = 0

    @property
    def points(self) -> int:
        return 3 * self.won + self.drawn

    @property
    def goal_difference(self) -> int:
        return self.goals_for - self.goals_against

    def as_dict(self) -> dict[str, int | str]:
        return {
            "team": self.team,
            "played": self.played,
            "won": self.won,
            "drawn": self.drawn,
            "lost": self.lost,
            "goals_for": self.goals_for,
            "goals_against": self.goals_against,
            "goal_difference": self.goal_difference,
            "points": self.points,
        }


def standings(rows: list[MatchRow], teams: list[str]) -> list[Standing]:
    table = {name: Standing(team=name) for name in teams}
    for row in rows:
        result = row.result
        if row.kind != "round_robin" or row.state not in COUNTED or not result:
            continue
        score = result.get("score") or {}
        red_goals, blue_goals = score.get("red"), score.get("blue")
        if red_goals is None or blue_goals is None:
            continue
        red = table.setdefault(result["red_team"], Standing(team=result["red_team"]))
        blue = table.setdefault(result["blue_team"], Standing(team=result["blue_team"]))
        for me, goals_for, goals_against in (
            (red, red_goals, blue_goals),
            (blue, blue_goals, red_goals),
        ):
            me.played += 1
            me.goals_for += goals_for
            me.goals_against += goals_against
        winner = result.get("winner")
        if winner == "red":
            red.won, blue.lost = red.won + 1, blue.lost + 1
        elif winner == "blue":
            blue.won, red.lost = blue.won + 1, red.lost + 1
        else:
            red.drawn, blue.drawn = red.drawn + 1, blue.drawn + 1
    return sorted(
        table.values(), key=lambda s: (-s.points, -s.goal_difference, -s.goals_for, s.team)
    )
