"""Standings of the round-robin matches: 3 points a win, 1 a draw.

Teams level on points are ordered by, in turn:

1. head-to-head: points, then goal difference, then goals scored in the matches between the
   teams that are level (a mini-table of those teams alone);
2. goal difference over all matches;
3. goals scored over all matches;
4. a drawing of lots: a fixed draw seeded by the tournament's name (the same every time the
   table is shown, announced in the table's ``decided_by``).

``decided_by`` of a standing names the rule that placed the team above the next one when both
had the same points.
"""

from __future__ import annotations

import hashlib
from collections.abc import Iterable
from dataclasses import dataclass
from itertools import groupby

from contracts import Tally
from tournament.state import MatchRow

HEAD_TO_HEAD = "head-to-head"
GOAL_DIFFERENCE = "goal difference"
GOALS = "goals scored"
LOTS = "drawing of lots"


@dataclass(slots=True)
class Standing(Tally):
    """A team's line of the table: its :class:`contracts.Tally`, points and the tie-break."""

    decided_by: str = ""  # the tie-break that placed this team above the next one

    @property
    def points(self) -> int:
        return 3 * self.won + self.drawn

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
            "decided_by": self.decided_by,
        }


@dataclass(frozen=True, slots=True)
class _Game:
    red: str
    blue: str
    red_goals: int
    blue_goals: int


def _games(rows: list[MatchRow]) -> list[_Game]:
    games = []
    for row in rows:
        result = row.result
        if row.kind != "round_robin" or not row.state.played or not result:
            continue
        score = result.get("score") or {}
        red, blue = score.get("red"), score.get("blue")
        if red is None or blue is None:
            continue
        games.append(_Game(str(result["red_team"]), str(result["blue_team"]), int(red), int(blue)))
    return games


def _table(games: Iterable[_Game], teams: Iterable[str]) -> dict[str, Standing]:
    table = {name: Standing(team=name) for name in teams}
    for game in games:
        red = table.setdefault(game.red, Standing(team=game.red))
        blue = table.setdefault(game.blue, Standing(team=game.blue))
        red.count(game.red_goals, game.blue_goals)
        blue.count(game.blue_goals, game.red_goals)
    return table


def _lot(seed: str, team: str) -> str:
    return hashlib.sha256(f"{seed}\0{team}".encode()).hexdigest()


def standings(rows: list[MatchRow], teams: list[str], *, seed: str = "") -> list[Standing]:
    """The table; ``seed`` (the tournament's name) fixes the drawing of lots."""
    games = _games(rows)
    table = _table(games, teams)
    ordered: list[Standing] = []
    by_points = sorted(table.values(), key=lambda s: -s.points)
    for _, group in groupby(by_points, key=lambda s: s.points):
        level = list(group)
        if len(level) == 1:
            ordered += level
            continue
        names = {s.team for s in level}
        mini = _table([g for g in games if g.red in names and g.blue in names], names)

        def key(s: Standing, mini: dict[str, Standing] = mini) -> tuple[object, ...]:
            h = mini[s.team]
            return (-h.points, -h.goal_difference, -h.goals_for,
                    -s.goal_difference, -s.goals_for, _lot(seed, s.team))

        level.sort(key=key)
        for upper, lower in zip(level, level[1:], strict=False):
            upper.decided_by = _rule(key(upper), key(lower))
        ordered += level
    return ordered


def _rule(upper: tuple[object, ...], lower: tuple[object, ...]) -> str:
    for index, name in ((0, HEAD_TO_HEAD), (1, HEAD_TO_HEAD), (2, HEAD_TO_HEAD),
                        (3, GOAL_DIFFERENCE), (4, GOALS)):
        if upper[index] != lower[index]:
            return name
    return LOTS
