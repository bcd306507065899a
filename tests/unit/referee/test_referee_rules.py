"""AutoRef rules as pure functions on hand-made snapshots."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import replace

import pytest

from contracts.field import KID_FIELD
from contracts.geometry import Pose
from contracts.ids import RobotId
from contracts.match_spec import GameType
from referee.config import TimingConfig
from referee.gamecontroller import GameState, Penalty, SecondaryState
from referee.gamecontroller.machine import SetPlay
from referee.rules import (
    ball_holding,
    ball_out,
    dropped_ball,
    end_of_game,
    fallen,
    goal,
    goalkeeper,
    kickoff,
    outside_turf,
    pushing,
    removal,
)
from referee.rules.base import (
    AwardSetPlay,
    DropBall,
    GameView,
    GiveCard,
    Goal,
    PenalizeRobot,
    free_kick,
)
from referee.snapshot import RobotState
from tests.unit.referee.referee_helpers import BLUE, RED, robot, snapshot

R1, R2, B1, B2 = RobotId(RED, 1), RobotId(RED, 2), RobotId(BLUE, 1), RobotId(BLUE, 2)


def view(**changes: object) -> GameView:
    values: dict[str, object] = dict(
        state=GameState.PLAYING,
        phase=SecondaryState.NORMAL,
        set_play=None,
        half=1,
        kickoff_team=RED,
        left_team=RED,
        ball_in_play=True,
        penalised=frozenset(),
        goalkeepers=frozenset({R1, B1}),
        field=KID_FIELD,
        timing=TimingConfig(),
    )
    values.update(changes)
    return GameView(**values)  # type: ignore[arg-type]


# --- goal -----------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("ball", "scoring"),
    [((4.58, 0.0, 0.07), RED), ((-4.58, 1.2, 0.07), BLUE), ((4.58, -1.29, 1.1), RED)],
)
def test_goal_when_fully_over_the_line(ball: tuple[float, float, float], scoring: object) -> None:
    decisions, _ = goal.judge(snapshot(100, ball=ball, toucher=R1), view(), goal.GoalMemory())
    assert decisions and isinstance(decisions[0], Goal) and decisions[0].scoring is scoring


@pytest.mark.parametrize(
    "ball",
    [(4.55, 0.0, 0.07), (4.6, 1.31, 0.07), (4.6, 0.0, 1.25)],
    ids=["on the line", "outside the post", "over the bar"],
)
def test_no_goal(ball: tuple[float, float, float]) -> None:
    decisions, _ = goal.judge(snapshot(100, ball=ball, toucher=R1), view(), goal.GoalMemory())
    assert not any(isinstance(d, Goal) for d in decisions)


def test_own_goal_counts_for_the_other_team() -> None:
    decisions, _ = goal.judge(
        snapshot(100, ball=(-4.6, 0.0, 0.07), toucher=R2), view(), goal.GoalMemory()
    )
    assert decisions == [Goal(BLUE, R2, True)]


def test_second_half_sides() -> None:
    decisions, _ = goal.judge(
        snapshot(100, ball=(-4.6, 0.0, 0.07), toucher=R2), view(left_team=BLUE), goal.GoalMemory()
    )
    assert decisions == [Goal(RED, R2, False)]


def test_no_goal_directly_from_indirect_free_kick_until_another_robot_touches() -> None:
    memory = goal.restart(goal.Restriction.INDIRECT_FREE_KICK)
    taker = robot(RED, 1, 3.0, 0.0, ball_contact=True)
    _, memory = goal.judge(snapshot(10, (taker,), ball=(3.1, 0.0, 0.07)), view(), memory)
    assert memory.taker == R1 and not memory.cleared
    decisions, memory = goal.judge(
        snapshot(20, ball=(4.6, 0.2, 0.07), toucher=R1), view(), memory
    )
    assert len(decisions) == 1 and isinstance(decisions[0], AwardSetPlay)
    assert decisions[0].kind is SecondaryState.GOAL_KICK and decisions[0].team is BLUE
    other = robot(RED, 2, 3.5, 0.0, ball_contact=True)
    _, memory = goal.judge(snapshot(30, (other,), ball=(3.6, 0.0, 0.07)), view(), memory)
    assert memory.cleared
    decisions, _ = goal.judge(snapshot(40, ball=(4.6, 0.2, 0.07), toucher=R2), view(), memory)
    assert decisions == [Goal(RED, R2, False)]


def test_the_kick_off_rules_do_not_hold_after_a_set_play() -> None:
    """hlvs_webots referee.py:2136-2138: the defending team's touch before the ball is in play
    is judged in the kick-off's phase only. After a throw-in the team that did not kick off
    takes it, touching the ball before it is in play, and is not removed."""
    from referee.rulebook import RuleBook

    rules = RuleBook()
    taker = robot(BLUE, 2, -1.0, 2.8, ball_contact=True)
    at = snapshot(10, (taker,), ball=(-1.0, 2.9, 0.07))
    in_throw_in = view(ball_in_play=False, kickoff_team=RED)
    rules.restart(at, goal.Restriction.THROW_IN)
    assert not [d for d in rules.judge(at, in_throw_in) if isinstance(d, PenalizeRobot)]
    rules.restart(at, goal.Restriction.KICKOFF)  # the same touch after a kick-off: removed
    found = [d for d in rules.judge(at, in_throw_in) if isinstance(d, PenalizeRobot)]
    assert [(d.robot, d.reason) for d in found] == [
        (RobotId(BLUE, 2), "touched the ball before it was in play")]


Touch = tuple[int, RobotState | None, tuple[float, float]]


def _kick_off_goal(touches: list[Touch]) -> list[object]:
    """Red kicked off; each (ms, robot touching or None, ball xy) is a snapshot; then the ball
    lies in blue's goal."""
    memory = goal.restart(goal.Restriction.KICKOFF)
    for ms, toucher, (x, y) in touches:
        robots = (toucher,) if toucher is not None else ()
        _, memory = goal.judge(snapshot(ms, robots, ball=(x, y, 0.07)), view(), memory)
    decisions, _ = goal.judge(snapshot(900, ball=(4.6, 0.2, 0.07), toucher=R1), view(), memory)
    return list(decisions)


def test_kick_off_ball_out_of_the_circle_and_in_without_a_touch_is_no_goal() -> None:
    """hlvs_webots referee.py:2158-2163, 2292-2295: leaving the circle alone does not make a
    kick-off's goal count; the kicker's touch inside it neither."""
    kicker = robot(RED, 1, -0.2, 0.0, ball_contact=True)
    decisions = _kick_off_goal([(10, kicker, (0.0, 0.0)), (20, None, (1.0, 0.0)),
                                (30, None, (3.0, 0.2))])  # fmt: skip
    assert len(decisions) == 1 and isinstance(decisions[0], AwardSetPlay)
    assert decisions[0].kind is SecondaryState.GOAL_KICK


def test_kick_off_goal_counts_after_a_touch_out_of_the_circle() -> None:
    """referee.py:2164-2168: the kicker touching the ball again after it left the circle."""
    kicker_at_centre = robot(RED, 1, -0.2, 0.0, ball_contact=True)
    kicker_out = robot(RED, 1, 2.9, 0.2, ball_contact=True)
    decisions = _kick_off_goal([(10, kicker_at_centre, (0.0, 0.0)), (20, None, (3.0, 0.2)),
                                (30, kicker_out, (3.0, 0.2))])  # fmt: skip
    assert decisions == [Goal(RED, R1, False)]


def test_kick_off_goal_counts_after_a_touch_by_the_defending_team() -> None:
    """referee.py:2158-2159: an opponent of the kick-off team touched it (inside the circle)."""
    defender = robot(BLUE, 2, 0.2, 0.0, ball_contact=True)
    decisions = _kick_off_goal([(10, defender, (0.1, 0.0))])
    assert decisions == [Goal(RED, R1, False)]


def test_kick_off_touch_recorded_between_snapshots_counts() -> None:
    """A touch the world recorded between two snapshots (its last toucher's time changed)."""
    memory = goal.restart(goal.Restriction.KICKOFF, snapshot(0))
    _, memory = goal.judge(snapshot(10, ball=(3.0, 0.2, 0.07)), view(), memory)
    touched = replace(snapshot(20, ball=(3.2, 0.2, 0.07), toucher=R1), last_ball_touch_ms=16)
    _, memory = goal.judge(touched, view(), memory)
    assert memory.cleared


def test_throw_in_into_own_goal_gives_corner() -> None:
    memory = goal.restart(goal.Restriction.THROW_IN)
    decisions, _ = goal.judge(snapshot(20, ball=(-4.6, 0.3, 0.07), toucher=R1), view(), memory)
    assert isinstance(decisions[0], AwardSetPlay)
    assert decisions[0].kind is SecondaryState.CORNER_KICK and decisions[0].team is BLUE


def _own_goal_after_goal_kick(touches: list[tuple[int, bool, bool]]) -> list[object]:
    """Blue took a goal kick (the league's ``interruption``: ``can_score_own`` False,
    referee.py:1709); each (ms, blue 1 touching, ball in play) is a snapshot; then the ball lies
    in blue's own goal (on the right: red on the left), last touched by blue 1."""
    memory = goal.restart(None, snapshot(0), BLUE)
    for ms, touching, in_play in touches:
        robots = (robot(BLUE, 1, 0.2, -2.9, ball_contact=True),) if touching else ()
        _, memory = goal.judge(snapshot(ms, robots), view(ball_in_play=in_play), memory)
    decisions, _ = goal.judge(snapshot(900, ball=(4.6, 0.3, 0.07), toucher=B1), view(), memory)
    return list(decisions)


def test_own_goal_straight_from_a_set_play_gives_a_corner_kick() -> None:
    """hlvs_webots referee.py:2305-2314: the taker touched the ball before it was in play and
    not since, so ``can_score_own`` is still False: no goal, a corner kick for the opponents
    (the league's ``goal_kick/scoring/own_goal`` and ``corner/scoring/own_goal``)."""
    decisions = _own_goal_after_goal_kick([(10, True, False), (20, False, False),
                                           (30, False, True)])  # fmt: skip
    assert len(decisions) == 1 and isinstance(decisions[0], AwardSetPlay)
    assert decisions[0].kind is SecondaryState.CORNER_KICK and decisions[0].team is RED


def test_own_goal_counts_once_the_ball_was_touched_in_play() -> None:
    """referee.py:2162, 2172-2174: a touch after the ball came into play (``in_play <
    ball_last_touch_time``) makes an own goal count (the league's ``scoring/own_goal``)."""
    decisions = _own_goal_after_goal_kick([(10, True, False), (20, False, True),
                                           (30, True, True)])  # fmt: skip
    assert decisions == [Goal(RED, B1, True)]


def test_own_goal_counts_once_an_opponent_touched_the_ball() -> None:
    """referee.py:2156-2157, 2173: a touch by the team that does not restart."""
    memory = goal.restart(None, snapshot(0), BLUE)
    opponent = robot(RED, 1, 0.2, -2.9, ball_contact=True)
    _, memory = goal.judge(snapshot(10, (opponent,)), view(ball_in_play=False), memory)
    assert memory.own_cleared
    decisions, _ = goal.judge(snapshot(900, ball=(4.6, 0.3, 0.07), toucher=B1), view(), memory)
    assert decisions == [Goal(RED, B1, True)]


def test_ball_in_play_counts_the_move_along_the_ground() -> None:
    """hlvs_webots referee.py:2140-2142: ``distance2`` (geometry.py:20-21, x and y) of the ball
    from its spot over ``BALL_IN_PLAY_MOVE`` 0.05: a ball lifted 6 cm where it lies is not in
    play; moved 5 cm along the ground it is."""
    from referee.rules import ball_in_play

    memory = ball_in_play.arm(snapshot(0, ball=(0.0, -2.975, 0.07)))
    waiting = view(ball_in_play=False)
    found, memory = ball_in_play.judge(snapshot(8, ball=(0.03, -2.975, 0.13)), waiting, memory)
    assert not found
    found, _ = ball_in_play.judge(snapshot(16, ball=(0.0, -2.924, 0.07)), waiting, memory)
    assert len(found) == 1


# --- ball out -------------------------------------------------------------------------------


def test_throw_in_placement_at_exit_x() -> None:
    """On the middle of the touch line, as the league's referee puts it (size_y -
    line_half_width, hlvs_webots referee.py:1731)."""
    decisions = ball_out.judge(snapshot(1, ball=(1.25, -3.08, 0.07), toucher=B1), view())
    assert decisions == [
        AwardSetPlay(SecondaryState.THROW_IN, RED, (1.25, -2.975), "ball over the touch line")
    ]


def test_corner_and_goal_kick_spots() -> None:
    """A goal kick's ball where the halfway line meets the touch line on the side the ball
    left, as hlvs_webots places it (referee.py:1747-1752)."""
    corner = ball_out.judge(snapshot(1, ball=(-4.6, 2.0, 0.07), toucher=R1), view())
    assert corner[0] == AwardSetPlay(
        SecondaryState.CORNER_KICK, BLUE, (-4.475, 2.975), "ball over the goal line"
    )
    kick = ball_out.judge(snapshot(1, ball=(-4.6, -2.0, 0.07), toucher=B1), view())
    assert kick[0] == AwardSetPlay(
        SecondaryState.GOAL_KICK, RED, (0.0, -2.975), "ball over the goal line"
    )


def test_ball_out_not_judged_during_set_play() -> None:
    play = SetPlay(SecondaryState.THROW_IN, RED, 0)
    assert ball_out.judge(snapshot(1, ball=(1.0, 3.2, 0.07)), view(set_play=play)) == []


# --- kick-off -------------------------------------------------------------------------------


def test_kickoff_positions() -> None:
    robots = (
        robot(RED, 1, -0.3, 0.0),  # kicking team may be in the circle
        robot(RED, 2, 0.4, 1.0),  # opponents' half
        robot(BLUE, 1, 0.6, 0.0),  # defender in the circle
        robot(BLUE, 2, 2.0, 3.3),  # outside the field
    )
    decisions = kickoff.judge_set(snapshot(1, robots), view(state=GameState.SET))
    penalised = {d.robot for d in decisions if isinstance(d, PenalizeRobot)}
    assert penalised == {R2, B1, B2}


# --- timers ---------------------------------------------------------------------------------


def test_fallen_after_timeout_only() -> None:
    memory = fallen.FallenMemory()
    timing = TimingConfig(fallen_s=20.0)
    down = (robot(BLUE, 2, 1.0, 1.0, fallen=True),)
    for ms in range(0, 20_001, 8):
        decisions, memory = fallen.judge(snapshot(ms, down), view(timing=timing), memory)
        assert decisions == []
    decisions, memory = fallen.judge(snapshot(20_008, down), view(timing=timing), memory)
    assert decisions == [PenalizeRobot(B2, Penalty.PICKUP_OR_INCAPABLE, "fallen down")]


def test_penalised_robots_are_not_judged_fallen() -> None:
    down = (robot(BLUE, 2, 1.0, 1.0, fallen=True),)
    game = view(penalised=frozenset({B2}), timing=TimingConfig(fallen_s=0.0))
    memory = fallen.FallenMemory()
    for ms in (0, 8, 16):
        decisions, memory = fallen.judge(snapshot(ms, down), game, memory)
        assert decisions == []


def test_outside_turf() -> None:
    game = view(timing=TimingConfig(outside_turf_s=1.0))
    memory = outside_turf.OutsideTurfMemory()
    out = (robot(RED, 1, 5.6, 0.0), robot(RED, 2, 5.4, 0.0))
    decisions, memory = outside_turf.judge(snapshot(0, out), game, memory)
    decisions, memory = outside_turf.judge(snapshot(1008, out), game, memory)
    assert [d.robot for d in decisions if isinstance(d, PenalizeRobot)] == [R1]


def test_dropped_ball() -> None:
    game = view(timing=TimingConfig(dropped_ball_s=120.0))
    memory = dropped_ball.DroppedBallMemory()
    decisions, memory = dropped_ball.judge(snapshot(0, ball=(1.0, 1.0, 0.07)), game, memory)
    decisions, memory = dropped_ball.judge(snapshot(119_000, ball=(1.04, 1.0, 0.07)), game, memory)
    assert decisions == []
    decisions, memory = dropped_ball.judge(snapshot(120_000, ball=(1.0, 1.0, 0.07)), game, memory)
    assert len(decisions) == 1 and isinstance(decisions[0], DropBall)


def test_inactive_goalkeeper_progress_resets() -> None:
    game = view(timing=TimingConfig(inactive_goalkeeper_s=20.0))
    memory = goalkeeper.GoalkeeperMemory()
    keeper = (robot(RED, 1, -4.2, 0.0),)
    _, memory = goalkeeper.judge(snapshot(0, keeper, ball=(-3.8, 0.0, 0.07)), game, memory)
    closer = (robot(RED, 1, -4.1, 0.0),)
    _, memory = goalkeeper.judge(snapshot(15_000, closer, ball=(-3.8, 0.0, 0.07)), game, memory)
    decisions, memory = goalkeeper.judge(
        snapshot(25_000, closer, ball=(-3.8, 0.0, 0.07)), game, memory
    )
    assert decisions == []
    decisions, _ = goalkeeper.judge(snapshot(35_100, closer, ball=(-3.8, 0.0, 0.07)), game, memory)
    assert decisions == [PenalizeRobot(R1, Penalty.PICKUP_OR_INCAPABLE, "inactive goalkeeper")]


# --- ball holding ---------------------------------------------------------------------------


def test_convex_hull_and_circle() -> None:
    hull = ball_holding.convex_hull([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)])
    assert len(hull) == 4
    assert ball_holding.circle_meets_hull((0.5, 0.5), 0.01, hull)
    assert ball_holding.circle_meets_hull((1.02, 0.5), 0.03, hull)
    assert not ball_holding.circle_meets_hull((1.1, 0.5), 0.03, hull)
    segment = ball_holding.convex_hull([(0.0, -0.2), (0.0, 0.2)])
    assert ball_holding.circle_meets_hull((0.01, 0.0), 0.02, segment)


def test_ball_holding_more_than_half_of_five_seconds() -> None:
    robots = (robot(RED, 1, 1.0, 0.15), robot(RED, 2, 1.0, -0.15))
    memory = ball_holding.BallHoldingMemory()
    found = []
    for ms in range(0, 2600, 8):
        decisions, memory = ball_holding.judge(
            snapshot(ms, robots, ball=(1.0, 0.0, 0.07)), view(), memory
        )
        found += [(ms, d) for d in decisions]
    assert len(found) == 1 and 2500 < found[0][0] <= 2516
    play = found[0][1]
    assert isinstance(play, AwardSetPlay) and play.kind is SecondaryState.DIRECT_FREEKICK
    assert play.team is BLUE and play.position == (1.0, 0.0)


# --- pushing --------------------------------------------------------------------------------


def test_sustained_contact_pusher_is_farther_from_ball() -> None:
    a = robot(RED, 1, 0.0, 1.5, contacts=(B1,))
    b = robot(BLUE, 1, 0.0, 1.2, contacts=(R1,))
    memory = pushing.PushingMemory()
    out = []
    for ms in range(0, 1100, 8):
        decisions, memory = pushing.judge(snapshot(ms, (a, b)), view(ball_in_play=False), memory)
        out += decisions
    assert PenalizeRobot(R1, Penalty.PHYSICAL_CONTACT, "pushing blue player 1") in out
    assert not [d for d in out if isinstance(d, GiveCard)]  # no card, as in the virtual league


def _approach(
    y_at: Callable[[int], float], until_ms: int, ball: tuple[float, float, float]
) -> list[object]:
    """Blue 2 at y_at(ms) comes down onto a still red 2 at y 0.3; it touches at ``until_ms``."""
    b = robot(RED, 2, 0.0, 0.3)
    memory = pushing.PushingMemory()
    decisions: list[object] = []
    for ms in range(0, until_ms + 8, 8):
        touching = ms >= until_ms
        a = robot(BLUE, 2, 0.0, y_at(ms), contacts=(R2,) if touching else ())
        red = robot(RED, 2, 0.0, 0.3, contacts=(B2,) if touching else ())
        found, memory = pushing.judge(snapshot(ms, (a, red if touching else b), ball=ball), view(),
                                      memory)  # fmt: skip
        decisions += found
    return decisions


def test_charging_near_ball_gives_free_kick() -> None:
    # 0.8 m/s over the last second, away from the ball's direction
    decisions = _approach(lambda ms: 1.4 - 0.8 * ms / 1000.0, 1000, ball=(0.5, 0.5, 0.07))
    kicks = [d for d in decisions if isinstance(d, AwardSetPlay)]
    assert kicks and kicks[0].kind is SecondaryState.DIRECT_FREEKICK and kicks[0].team is RED
    assert "charging" in kicks[0].reason


def test_charging_speed_is_the_average_over_one_second() -> None:
    # a sway: fast for the last 40 ms, but 0.1 m/s on average over the second: not a charge
    def sway(ms: int) -> float:
        return 0.7 - 0.1 * ms / 1000.0 - (0.03 * (ms - 960) / 40.0 if ms > 960 else 0.0)

    decisions = _approach(sway, 1000, ball=(0.5, 0.5, 0.07))
    assert not [d for d in decisions if isinstance(d, AwardSetPlay | PenalizeRobot)]


def test_a_placed_robot_starts_its_average_again() -> None:
    # teleported 3 m at 500 ms, then still: the jump is not a speed
    decisions = _approach(lambda ms: 3.7 if ms < 500 else 0.6, 1000, ball=(0.5, 0.5, 0.07))
    assert not [d for d in decisions if isinstance(d, AwardSetPlay | PenalizeRobot)]


def _contact(
    a_track: Callable[[int], tuple[float, float]],
    b_track: Callable[[int], tuple[float, float]],
    touch_ms: int,
    ball: tuple[float, float, float],
    *,
    a: RobotId = B2,
    b: RobotId = R2,
    end_ms: int | None = None,
    **changes: object,
) -> list[tuple[int, object]]:
    """Robots ``a`` and ``b`` on their tracks (ms -> xy), touching from ``touch_ms``."""
    memory = pushing.PushingMemory()
    found: list[tuple[int, object]] = []
    for ms in range(0, (end_ms or touch_ms) + 8, 8):
        touching = ms >= touch_ms
        ra = robot(a.team, a.number, *a_track(ms), contacts=(b,) if touching else ())
        rb = robot(b.team, b.number, *b_track(ms), contacts=(a,) if touching else ())
        decisions, memory = pushing.judge(snapshot(ms, (ra, rb), ball=ball), view(**changes),
                                          memory)  # fmt: skip
        found += [(ms, d) for d in decisions]
    return found


def test_charging_from_behind_on_the_way_to_the_ball() -> None:
    """referee.py:1000-1006: both move to the ball, blue 2 (0.4 m/s) more than 0.1 m farther:
    it charges from behind; 1.4 m from the ball, a removal (904-928)."""
    found = _contact(
        lambda ms: (0.0, -0.2 + 0.4 * ms / 1000.0),  # blue 2 behind, faster
        lambda ms: (0.0, 0.3 + 0.1 * ms / 1000.0),
        1000,
        ball=(0.0, 1.6, 0.07),
    )
    assert [d for _, d in found] == [
        PenalizeRobot(B2, Penalty.PHYSICAL_CONTACT, "charging red player 2 from behind")]


def test_violent_collision_away_from_the_ball() -> None:
    """referee.py:1007-1011: more than 2 m from the ball, 0.2 m/s faster than the other."""
    found = _contact(lambda ms: (0.5 - 0.5 * ms / 1000.0, 0.0),
                     lambda ms: (-0.2, 0.0), 1000, ball=(3.0, 2.0, 0.07))  # fmt: skip
    assert len(found) == 1 and isinstance(found[0][1], PenalizeRobot)
    assert found[0][1].robot == B2 and "violent collision" in found[0][1].reason


def test_a_slow_robot_away_from_the_ball_is_no_foul() -> None:
    found = _contact(lambda ms: (0.15 - 0.15 * ms / 1000.0, 0.0),
                     lambda ms: (-0.2, 0.0), 1000, ball=(3.0, 2.0, 0.07))  # fmt: skip
    assert found == []


def test_touching_a_goalkeeper_in_its_goal_area_is_a_foul() -> None:
    """referee.py:962-965: any contact with a goalkeeper inside its own goal area, at any
    speed; blue 1 is blue's goalkeeper, blue defends x > 0 (red on the left)."""
    found = _contact(lambda ms: (3.6, 0.2), lambda ms: (4.0, 0.2), 500, ball=(3.0, 0.0, 0.07),
                     a=R2, b=B1)  # fmt: skip
    assert len(found) == 1 and isinstance(found[0][1], AwardSetPlay)
    assert found[0][1].team is BLUE and "goalkeeper" in found[0][1].reason
    assert found[0][1].kind is SecondaryState.DIRECT_FREEKICK


def test_every_step_of_a_contact_is_judged() -> None:
    """referee.py:1019-1027: the tree runs on every step two robots touch, not only when the
    contact begins: blue 2 leans on red 2 slowly, then speeds up away from the ball (before
    the contact lasted the 1 s of a sustained push)."""
    def blue(ms: int) -> tuple[float, float]:
        return (0.0, 0.6 - (0.05 * ms if ms < 1500 else 75.0 + 0.8 * (ms - 1500)) / 1000.0)

    found = _contact(blue, lambda ms: (0.0, 0.3), 1000, ball=(0.5, 0.5, 0.07), end_ms=1900)
    assert found and found[0][0] > 1500
    kick = found[0][1]
    assert isinstance(kick, AwardSetPlay) and kick.kind is SecondaryState.DIRECT_FREEKICK


def test_the_free_kick_is_taken_where_the_offender_stood() -> None:
    """referee.py:926-928: ``offence_location`` is the offender's position."""
    found = _contact(lambda ms: (0.0, 1.4 - 0.8 * ms / 1000.0), lambda ms: (0.0, 0.3), 1000,
                     ball=(0.5, 0.5, 0.07))  # fmt: skip
    kick = found[0][1]
    assert isinstance(kick, AwardSetPlay) and kick.position == pytest.approx((0.0, 0.6))


def test_both_robots_are_immune_for_two_seconds_after_a_foul() -> None:
    found = _contact(lambda ms: (0.0, 1.4 - 0.8 * min(ms, 1000) / 1000.0), lambda ms: (0.0, 0.3),
                     1000, ball=(0.5, 0.5, 0.07), end_ms=2900)  # fmt: skip
    assert [ms for ms, _ in found] == [1000]


# --- removal and end of game ----------------------------------------------------------------


def test_reentry_pose_side_and_shift() -> None:
    template = Pose(x_m=-3.0, y_m=-3.1, yaw_rad=1.57)
    pose = removal.reentry_pose(
        template=template, side_sign=1.0, ball_y_m=-1.0, occupied=[], field=KID_FIELD
    )
    assert (pose.x_m, pose.y_m) == (3.0, 3.1) and pose.yaw_rad == pytest.approx(-math.pi / 2)
    shifted = removal.reentry_pose(
        template=template, side_sign=-1.0, ball_y_m=1.0, occupied=[(-3.0, -3.1)],
        field=KID_FIELD,
    )
    assert (shifted.x_m, shifted.y_m) == pytest.approx((-3.6, -3.1))


@pytest.mark.parametrize(
    ("game_type", "phase", "half", "score", "expected"),
    [
        (GameType.NORMAL, SecondaryState.NORMAL, 1, (0, 0), end_of_game.Next.SECOND_HALF),
        (GameType.NORMAL, SecondaryState.NORMAL, 2, (1, 1), end_of_game.Next.FINISHED),
        (GameType.KNOCKOUT, SecondaryState.NORMAL, 2, (1, 1), end_of_game.Next.OVERTIME),
        (GameType.KNOCKOUT, SecondaryState.NORMAL, 2, (2, 1), end_of_game.Next.FINISHED),
        (GameType.KNOCKOUT, SecondaryState.OVERTIME, 1, (1, 1),
         end_of_game.Next.OVERTIME_SECOND_HALF),
        (GameType.KNOCKOUT, SecondaryState.OVERTIME, 2, (1, 1), end_of_game.Next.SHOOTOUT),
    ],
)
def test_after_period(
    game_type: GameType, phase: SecondaryState, half: int, score: tuple[int, int],
    expected: end_of_game.Next,
) -> None:
    got = end_of_game.after_period(
        game_type=game_type, phase=phase, half=half, score={RED: score[0], BLUE: score[1]}
    )
    assert got is expected


@pytest.mark.parametrize(
    ("taken", "scored", "decided", "winner"),
    [
        ((3, 3), (3, 0), True, RED),  # blue cannot catch up with 2 left
        ((3, 2), (3, 0), False, None),
        ((5, 5), (2, 2), False, None),  # extended
        ((6, 5), (3, 2), False, None),
        ((6, 6), (3, 2), True, RED),
        ((5, 4), (4, 4), False, None),
        ((5, 5), (4, 5), True, BLUE),
    ],
)
def test_shootout_status(
    taken: tuple[int, int], scored: tuple[int, int], decided: bool, winner: object
) -> None:
    status = end_of_game.shootout_status(
        taken={RED: taken[0], BLUE: taken[1]}, scored={RED: scored[0], BLUE: scored[1]}
    )
    assert (status.decided, status.winner) == (decided, winner)


def test_shootout_coin_toss_is_seeded() -> None:
    results = {
        end_of_game.shootout_status(
            taken={RED: 10, BLUE: 10}, scored={RED: 1, BLUE: 1}, seed=seed
        ).winner
        for seed in range(20)
    }
    assert results == {RED, BLUE}
    again = end_of_game.shootout_status(taken={RED: 10, BLUE: 10}, scored={RED: 1, BLUE: 1}, seed=4)
    assert again.coin_toss and again.winner is end_of_game.shootout_status(
        taken={RED: 10, BLUE: 10}, scored={RED: 1, BLUE: 1}, seed=4
    ).winner


def test_a_free_kick_with_the_ball_fully_in_the_penalty_area_is_a_penalty_kick() -> None:
    """hlvs_webots referee.py:1682-1704 (field.py:55-58): a free kick awarded while the ball
    lies fully inside the penalty area of the offenders becomes a penalty kick on the penalty
    mark; the ball touching the area's line keeps it a direct free kick."""
    game = view()  # red defends x < 0
    inside = free_kick(BLUE, (-3.0, -0.4), (-3.0, -0.65, 0.07), game, "ball holding")
    assert inside == AwardSetPlay(SecondaryState.PENALTYKICK, BLUE, (-3.0, 0.0), "ball holding")
    on_line = free_kick(BLUE, (-2.5, 0.0), (-2.52, 0.0, 0.07), game, "ball holding")
    assert on_line == AwardSetPlay(
        SecondaryState.DIRECT_FREEKICK, BLUE, (-2.5, 0.0), "ball holding"
    )
    # red attacks x > 0: a foul by blue with the ball in blue's area is red's penalty kick
    ball = (3.6, 1.0, 0.07)
    assert free_kick(RED, (3.5, 1.0), ball, game, "x").kind is SecondaryState.PENALTYKICK
    assert free_kick(BLUE, (3.5, 1.0), ball, game, "x").kind is SecondaryState.DIRECT_FREEKICK
