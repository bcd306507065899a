"""A set play's ball, placed as the league's referee places it (hlvs_webots referee.py:2425-2430,
``game_interruption_place_ball`` 1874-1903 with 1794-1872): left where it is through sub-phase
0, placed when sub-phase 0 ends, the spot first cleared of penalised and fallen robots, another
spot tried, robots pushed away. And the rules around it: robots' positions at a penalty kick's
EXECUTE, opponents near the ball after a set play until it is in play, a penalised robot back
on the field."""

from __future__ import annotations

from contracts.field import KID_FIELD
from contracts.geometry import Pose
from contracts.ids import RobotId
from referee import FakeClock, Referee
from referee.config import TimingConfig
from referee.gamecontroller import Card, GameState, Penalty, SecondaryState
from referee.gamecontroller.machine import SetPlay
from referee.placement import alternative_spots, pushed_away
from referee.rules import removal, set_play
from referee.rules.base import GameView, PenalizeRobot
from referee.snapshot import PlaceBall, RobotState, SetLimp, TeleportRobot, WorldCommand
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot

R1, R2, B1, B2 = RobotId(RED, 1), RobotId(RED, 2), RobotId(BLUE, 1), RobotId(BLUE, 2)
SPOT = (0.0, 2.975)  # a goal kick's, the ball over blue's goal line at y > 0
RED_FAR, BLUE_FAR = robot(RED, 1, -2.0, 0.0), robot(BLUE, 1, 2.0, 0.0)
# at their start positions off the field (checked when READY begins) until READY
START = (robot(RED, 1, -2.0, -3.2, hull=False), robot(BLUE, 1, 2.0, -3.2, hull=False))


class Game:
    def __init__(self) -> None:
        self.clock = FakeClock()
        self.ref = Referee(config=make_config(side_left=RED), clock=self.clock)
        self.ms = 0

    def step(
        self, robots: tuple[RobotState, ...], ball: tuple[float, float, float]
    ) -> list[WorldCommand]:
        if self.ref.gc.state is GameState.INITIAL:
            robots = START
        commands = list(self.ref.step(snapshot(self.ms, robots, ball=ball)))
        self.clock.advance(0.008)
        self.ms += 8
        return commands

    def goal_kick(self, robots: tuple[RobotState, ...] = (RED_FAR, BLUE_FAR)) -> list[WorldCommand]:
        """Plays to PLAYING, puts the ball over blue's goal line (a goal kick for blue) and
        returns the commands of the step that awarded it."""
        while self.ref.gc.state is not GameState.PLAYING:
            self.step(robots, (0.0, 0.0, 0.07))
        commands = self.step(robots, (4.7, 1.0, 0.07))
        play = self.ref.gc.set_play
        assert play is not None and play.kind is SecondaryState.GOAL_KICK and play.team is BLUE
        assert self.ref.set_play_spot == SPOT
        return commands

    def through_sub_phase_0(
        self, robots: tuple[RobotState, ...], ball: tuple[float, float, float]
    ) -> tuple[list[WorldCommand], list[WorldCommand]]:
        """Steps until sub-phase 0 is over: (the commands before, those of the step it
        ended)."""
        before: list[WorldCommand] = []
        while True:
            commands = self.step(robots, ball)
            play = self.ref.gc.set_play
            if play is not None and play.sub_phase != 0:
                return before, commands
            before += commands


def _placed(x: float, y: float) -> PlaceBall:
    return PlaceBall(position=(x, y, KID_FIELD.ball_radius_m))


def test_the_ball_is_left_where_it_is_in_sub_phase_0_and_placed_when_it_ends() -> None:
    game = Game()
    assert not any(isinstance(c, PlaceBall) for c in game.goal_kick())
    before, ending = game.through_sub_phase_0((RED_FAR, BLUE_FAR), (4.9, 1.2, 0.07))
    assert before == []  # the ball out of the field stays there
    assert ending == [_placed(*SPOT)]


def test_a_robot_near_the_spot_is_pushed_half_a_metre_from_it_keeping_its_heading() -> None:
    """A goal kick has no other spot (referee.py:1808-1828), so a red robot 0.2 m from it is
    moved along the line from the spot through it, to 0.5 m (kid) from the spot."""
    game = Game()
    game.goal_kick()
    near = robot(RED, 1, SPOT[0] - 0.2, SPOT[1])
    _, ending = game.through_sub_phase_0((near, BLUE_FAR), (4.9, 1.2, 0.07))
    assert ending == [
        TeleportRobot(robot=R1, pose=Pose(x_m=SPOT[0] - 0.5, y_m=SPOT[1], yaw_rad=0.0)),
        _placed(*SPOT),
    ]


def test_a_fallen_robot_near_the_spot_is_penalised_and_removed() -> None:
    game = Game()
    game.goal_kick()
    fallen = robot(RED, 1, SPOT[0] + 0.1, SPOT[1] - 0.2, fallen=True)
    _, ending = game.through_sub_phase_0((fallen, BLUE_FAR), (4.9, 1.2, 0.07))
    assert game.ref.gc.robot(R1).penalty is Penalty.PICKUP_OR_INCAPABLE
    moved = [c for c in ending if isinstance(c, TeleportRobot)]
    assert len(moved) == 1 and moved[0].robot == R1
    assert moved[0].pose.y_m < -KID_FIELD.half_width_m  # at its re-entry spot, away from the ball
    assert SetLimp(robot=R1, limp=True) in ending
    assert ending[-1] == _placed(*SPOT)


def test_a_penalised_robot_near_the_spot_is_put_at_its_reentry_spot_again() -> None:
    """Its penalty runs on: it is only carried away again (referee.py:1794-1798)."""
    game = Game()
    game.goal_kick()
    game.ref.gc.penalize(R1, Penalty.PICKUP_OR_INCAPABLE)
    left = game.ref.gc.robot(R1).left_ms
    penalised = robot(RED, 1, SPOT[0] - 0.3, SPOT[1] + 0.1)
    _, ending = game.through_sub_phase_0((penalised, BLUE_FAR), (4.9, 1.2, 0.07))
    moved = [c for c in ending if isinstance(c, TeleportRobot)]
    assert len(moved) == 1 and moved[0].robot == R1 and moved[0].pose.y_m < 0
    assert game.ref.gc.robot(R1).penalty is Penalty.PICKUP_OR_INCAPABLE
    assert game.ref.gc.robot(R1).left_ms == left  # the clock stands still in a set play
    assert ending[-1] == _placed(*SPOT)


def test_other_spots_are_tried_towards_the_attacked_goal_for_free_kicks_and_throw_ins() -> None:
    """referee.py:1808-1828: a free kick tries 0.5 m steps towards the goal attacked, away
    from the nearer touch line, towards it and back, then farther; a throw-in along the touch
    line; other set plays none."""
    free = alternative_spots(SecondaryState.DIRECT_FREEKICK, (1.0, 2.0), 1.0, 0.5)
    assert free[:5] == [(1.5, 2.0), (1.0, 1.5), (1.0, 2.5), (0.5, 2.0), (2.0, 2.0)]
    assert len(free) == 20
    throw_in = alternative_spots(SecondaryState.THROW_IN, (1.0, -2.975), -1.0, 0.5)
    assert throw_in[:2] == [(0.5, -2.975), (0.0, -2.975)]
    assert throw_in[5:7] == [(1.5, -2.975), (2.0, -2.975)]
    assert alternative_spots(SecondaryState.GOAL_KICK, SPOT, 1.0, 0.5) == []
    assert alternative_spots(SecondaryState.PENALTYKICK, (-3.0, 0.0), -1.0, 0.5) == []


def test_robots_pushed_away_do_not_land_on_each_other() -> None:
    """The league's penalty kick scenario (tests/game_interruptions/penalty_kick/scenario_1):
    the ball on the mark at (-3, 0), red 2 at (-3, -0.4) and blue 3 at (-3, -0.1) near it, red
    3 at (-3, -0.9): blue 3 (moved first) lands 1.5 m from the spot, red 2 2 m."""
    where = {
        RobotId(RED, 1): (-2.0, -2.0), RobotId(RED, 2): (-3.0, -0.4),
        RobotId(RED, 3): (-3.0, -0.9), RobotId(BLUE, 3): (-3.0, -0.1),
    }  # fmt: skip
    moved = pushed_away(where, (-3.0, 0.0), 0.5)
    assert moved.keys() == {RobotId(BLUE, 3), RobotId(RED, 2)}
    assert moved[RobotId(BLUE, 3)] == (-3.0, -1.5)
    assert moved[RobotId(RED, 2)] == (-3.0, -2.0)


def test_a_free_kick_spot_taken_by_robots_moves_the_ball_towards_the_attacked_goal() -> None:
    """A free kick for blue (attacking x < 0 here, red on the left) at (1, 2) with a red robot
    on it: the first spot clear of robots, 0.5 m towards red's goal."""
    game = Game()
    while game.ref.gc.state is not GameState.PLAYING:
        game.step((RED_FAR, BLUE_FAR), (0.0, 0.0, 0.07))
    from referee.rules.base import AwardSetPlay

    game.ref.apply(  # a free kick, as the ball-holding rule awards it
        [AwardSetPlay(SecondaryState.DIRECT_FREEKICK, BLUE, (1.0, 2.0), "test")],
        snapshot(game.ms, (RED_FAR, BLUE_FAR), ball=(1.0, 2.0, 0.07)),
    )
    on_spot = robot(RED, 1, 1.1, 2.0)
    _, ending = game.through_sub_phase_0((on_spot, BLUE_FAR), (1.0, 2.0, 0.07))
    assert ending == [_placed(0.5, 2.0)]


def _view(play: SetPlay | None, *, in_play: bool = False,
          keepers: frozenset[RobotId] = frozenset()) -> GameView:  # fmt: skip
    return GameView(
        state=GameState.PLAYING, phase=SecondaryState.NORMAL, set_play=play, half=1,
        kickoff_team=RED, left_team=RED, ball_in_play=in_play, penalised=frozenset(),
        goalkeepers=keepers, field=KID_FIELD, timing=TimingConfig(),
    )  # fmt: skip


def test_penalty_kick_positions_at_execute() -> None:
    """The league's scenario (penalty_kick/scenario_1, referee.py:1180-1209): blue's penalty
    kick on red's mark at (-3, 0). Red 1, red's goalkeeper, on its goal line: fine; red 2 on
    the goal line and red 3 beyond the mark: removed; red 4 behind the mark: fine; blue 1
    beyond the mark: removed; blue 2 near the ball: the striker; blue 3 near it too: removed."""
    robots: tuple[RobotState, ...] = (
        robot(RED, 1, -4.5, 0.0), robot(RED, 2, -4.5, 0.5), robot(RED, 3, -3.1, 2.5),
        robot(RED, 4, -2.5, 2.5), robot(BLUE, 1, -4.5, -0.5), robot(BLUE, 2, -2.8, -0.2),
        robot(BLUE, 3, -2.8, 0.2),
    )  # fmt: skip
    play = SetPlay(SecondaryState.PENALTYKICK, BLUE, 2)
    view = _view(None, keepers=frozenset({R1, B1}))
    decisions = set_play.judge_penalty_kick_positions(
        snapshot(0, robots, ball=(-3.0, 0.0, 0.07)), view, play
    )
    removed = [d.robot for d in decisions if isinstance(d, PenalizeRobot)]
    assert removed == [RobotId(RED, 2), RobotId(RED, 3), B1, RobotId(BLUE, 3)]
    assert all(d.penalty is Penalty.PICKUP_OR_INCAPABLE for d in decisions)  # type: ignore[union-attr]
    # the goalkeeper off its line, between it and the mark: removed
    robots = (robot(RED, 1, -3.8, 0.0), robot(BLUE, 2, -2.8, -0.2))
    decisions = set_play.judge_penalty_kick_positions(
        snapshot(0, robots, ball=(-3.0, 0.0, 0.07)), view, play
    )
    assert [d.robot for d in decisions] == [R1]  # type: ignore[union-attr]
    # the judgement is part of a penalty kick's EXECUTE, not of a free kick's
    assert set_play.judge_execute(snapshot(0, robots, ball=(-3.0, 0.0, 0.07)), view, play)
    free = SetPlay(SecondaryState.DIRECT_FREEKICK, BLUE, 2)
    assert set_play.judge_execute(snapshot(0, robots, ball=(-3.0, 0.0, 0.07)), view, free) == []


def test_opponents_near_the_ball_after_a_set_play_until_it_is_in_play() -> None:
    """referee.py:2131-2135: after blue's set play was taken, a red robot nearer than 0.75 m
    to the ball is removed; a blue one is not; once the ball is in play, nobody."""
    robots = (robot(RED, 1, 1.5, 0.3), robot(BLUE, 1, 1.2, 0.0))
    snap = snapshot(0, robots, ball=(1.0, 0.0, 0.07))
    decisions = set_play.judge_before_in_play(snap, _view(None), BLUE)
    assert decisions == [
        PenalizeRobot(R1, Penalty.PICKUP_OR_INCAPABLE,
                      "closer than 0.75 m to the ball before it was in play after a set play")
    ]  # fmt: skip
    assert set_play.judge_before_in_play(snap, _view(None, in_play=True), BLUE) == []
    assert set_play.judge_before_in_play(snap, _view(None), None) == []  # after a kick-off
    far = snapshot(0, (robot(RED, 1, 1.8, 0.0),), ball=(1.0, 0.0, 0.07))
    assert set_play.judge_before_in_play(far, _view(None), BLUE) == []


def test_a_penalised_robot_back_on_the_field_gets_a_yellow_then_a_red_card() -> None:
    """referee.py:1287-1302 (and send_penalty 894-897): a penalised robot on the field is shown
    a yellow card and removed again; the second time the card is red and it is sent off. At its
    re-entry spot on the touch line it is not on the field."""
    game = Game()
    while game.ref.gc.state is not GameState.PLAYING:
        game.step((RED_FAR, BLUE_FAR), (0.0, 0.0, 0.07))
    game.ref.apply(
        [PenalizeRobot(R1, Penalty.PICKUP_OR_INCAPABLE, "test")],
        snapshot(game.ms, (RED_FAR, BLUE_FAR)),
    )
    at_reentry = robot(RED, 1, -3.0, -3.0)
    assert removal.penalised_in_field(
        snapshot(0, (at_reentry,)), frozenset({R1}), KID_FIELD, {}
    ) == []
    # a team whose re-entry pose is on the field: standing where the referee put it is no entry
    put_there = robot(RED, 1, -2.0, -1.0)
    assert removal.penalised_in_field(
        snapshot(0, (put_there,)), frozenset({R1}), KID_FIELD, {R1: (-2.0, -1.1)}
    ) == []
    assert removal.penalised_in_field(
        snapshot(0, (put_there,)), frozenset({R1}), KID_FIELD, {R1: (-3.0, -3.1)}
    ) == [R1]
    commands = game.step((at_reentry, BLUE_FAR), (0.0, 0.0, 0.07))
    assert game.ref.gc.robot(R1).yellow_cards == 0 and commands == []
    commands = game.step((RED_FAR, BLUE_FAR), (0.0, 0.0, 0.07))  # walked back in
    info = game.ref.gc.robot(R1)
    assert info.yellow_cards == 1 and info.penalty is Penalty.PICKUP_OR_INCAPABLE
    assert info.left_ms == round(game.ref.config.timing.removal_penalty_s * 1000)
    assert any(isinstance(c, TeleportRobot) and c.robot == R1 for c in commands)
    game.step((RED_FAR, BLUE_FAR), (0.0, 0.0, 0.07))
    info = game.ref.gc.robot(R1)
    assert info.red_cards == 1 and R1 in game.ref.book.red_carded
    assert [e.details.get("card") for e in game.ref.events if e.type == "card"] == [
        Card.YELLOW.value, Card.RED.value,
    ]  # fmt: skip


def test_a_removed_robot_is_put_on_its_spot_again_five_steps_later() -> None:
    """referee.py:1512-1514 with 1460-1474: the league's referee puts a robot it placed on its
    spot again, physics reset, 5 steps (40 ms) later, whatever moved it meanwhile."""
    game = Game()
    while game.ref.gc.state is not GameState.PLAYING:
        game.step((RED_FAR, BLUE_FAR), (0.0, 0.0, 0.07))
    placed = game.ref.apply(
        [PenalizeRobot(R1, Penalty.PICKUP_OR_INCAPABLE, "test")],
        snapshot(game.ms, (RED_FAR, BLUE_FAR)),
    )
    [spot] = [c for c in placed if isinstance(c, TeleportRobot)]
    again = []
    for _ in range(8):  # pushed a little after it was put there (still off the field)
        commands = game.step((robot(RED, 1, -3.0, -3.05), BLUE_FAR), (0.0, 0.0, 0.07))
        again.append([c for c in commands if isinstance(c, TeleportRobot)])
    assert again == [[]] * 5 + [[spot]] + [[]] * 2  # the first step is the one it was put at
