"""One counter of played, won, drawn, lost and goals for every table: the round robin's
standings and the ladder count with it."""

from __future__ import annotations

from contracts import Tally


def test_the_goals_decide_unless_an_outcome_is_given() -> None:
    tally = Tally(team="Alpha")
    tally.count(2, 1)
    tally.count(0, 0)
    tally.count(1, 3)
    tally.count(0, 0, "won")  # a forfeit: recorded 0:0, won by one side
    assert (tally.played, tally.won, tally.drawn, tally.lost) == (4, 2, 1, 1)
    assert (tally.goals_for, tally.goals_against, tally.goal_difference) == (3, 4, -1)


def test_the_standings_and_the_ladder_count_with_it() -> None:
    from service.ratings import TeamRating
    from tournament import Standing

    for line in (Standing(team="Alpha"), TeamRating(team="Alpha")):
        assert isinstance(line, Tally)
        line.count(1, 0)
        assert (line.played, line.won, line.goals_for) == (1, 1, 1)
    standing = Standing(team="Alpha")
    standing.count(1, 1)
    standing.count(2, 0)
    assert standing.points == 4 and standing.as_dict()["goal_difference"] == 2
