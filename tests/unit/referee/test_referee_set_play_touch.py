"""A ball touched before a set play is taken, as the league's referee judges it: by an opponent
of the set-play team, the set play is retaken (RETAKE, the ball placed again when sub-phase 0
ends); by the set-play
team, it is aborted and the ball is in play (ABORT); a warning either way. Touching it in
sub-phase 0 is allowed."""

from __future__ import annotations

from contracts.field import KID_FIELD
from contracts.ids import RobotId
from referee import FakeClock, Referee
from referee.config import TimingConfig
from referee.gamecontroller import Card, GameState, SecondaryState
from referee.gamecontroller.machine import SetPlay
from referee.rules import set_play
from referee.rules.base import AbortSetPlay, GameView, GiveCard, RetakeSetPlay
from referee.snapshot import PlaceBall, RobotState
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot

R1, B1 = RobotId(RED, 1), RobotId(BLUE, 1)


def _view(play: SetPlay | None) -> GameView:
    return GameView(
        state=GameState.PLAYING, phase=SecondaryState.NORMAL, set_play=play, half=1,
        kickoff_team=RED, left_team=RED, ball_in_play=False, penalised=frozenset(),
        goalkeepers=frozenset(), field=KID_FIELD, timing=TimingConfig(),
    )  # fmt: skip


def test_a_touch_in_sub_phase_1_or_2_retakes_or_aborts_and_warns() -> None:
    red_touches = snapshot(0, (robot(RED, 1, 3.3, 1.5, ball_contact=True),), ball=(3.5, 1.5, 0.07))
    blue_touches = snapshot(0, (robot(BLUE, 1, 3.7, 1.5, ball_contact=True),),
                            ball=(3.5, 1.5, 0.07))  # fmt: skip
    for phase in (1, 2):
        play = SetPlay(SecondaryState.GOAL_KICK, BLUE, phase)
        retake = set_play.judge_touch(red_touches, _view(play))
        assert [type(d) for d in retake] == [RetakeSetPlay, GiveCard]
        assert retake[0].robot == R1 and retake[1].card is Card.WARNING  # type: ignore[union-attr]
        abort = set_play.judge_touch(blue_touches, _view(play))
        assert [type(d) for d in abort] == [AbortSetPlay, GiveCard]
        assert abort[0].robot == B1  # type: ignore[union-attr]
    early = SetPlay(SecondaryState.GOAL_KICK, BLUE, 0)
    assert set_play.judge_touch(red_touches, _view(early)) == []
    assert set_play.judge_touch(red_touches, _view(None)) == []


def _step(ref: Referee, clock: FakeClock, ms: int, robots: tuple[RobotState, ...],
          ball: tuple[float, float, float]) -> list[object]:  # fmt: skip
    commands: list[object] = list(ref.step(snapshot(ms, robots, ball=ball)))
    clock.advance(0.008)
    return commands


def test_the_referee_retakes_then_aborts_a_goal_kick() -> None:
    """Red (on the left) plays the ball over blue's goal line: a goal kick for blue. Red touches
    the ball in sub-phase 1: it is retaken from sub-phase 0, the ball placed again when that
    ends, red 1 warned. Blue touches it in sub-phase 1: aborted, the ball in play, blue 1 warned."""
    clock = FakeClock()
    ref = Referee(config=make_config(side_left=RED), clock=clock)
    red_far, blue_far = robot(RED, 1, -2.0, 0.0), robot(BLUE, 1, 2.0, 0.0)
    ms = 0
    while ref.gc.state is not GameState.PLAYING:
        _step(ref, clock, ms, (red_far, blue_far), (0.0, 0.0, 0.07))
        ms += 8
    _step(ref, clock, ms, (red_far, blue_far), (4.7, 1.0, 0.07))  # over blue's goal line
    ms += 8
    play = ref.gc.set_play
    assert play is not None and play.kind is SecondaryState.GOAL_KICK and play.team is BLUE
    spot = ref.set_play_spot
    # the halfway line on the middle of the touch line, on the side the ball left
    assert spot == (0.0, 2.975)
    ball = (spot[0], spot[1], 0.07)
    placed = PlaceBall(position=(spot[0], spot[1], KID_FIELD.ball_radius_m))
    commands = []
    while ref.gc.set_play is not None and ref.gc.set_play.sub_phase == 0:
        commands += _step(ref, clock, ms, (red_far, blue_far), ball)
        ms += 8
    assert commands == [placed]  # placed once, when sub-phase 0 ends
    red_touch = robot(RED, 1, spot[0] - 0.1, spot[1], ball_contact=True)
    commands = _step(ref, clock, ms, (red_touch, blue_far), ball)
    ms += 8
    play = ref.gc.set_play
    assert play is not None and play.sub_phase == 0 and play.team is BLUE
    assert placed not in commands  # left where it is in sub-phase 0 again
    assert ref.gc.robot(R1).warnings == 1
    commands = []
    while ref.gc.set_play is not None and ref.gc.set_play.sub_phase == 0:
        commands += _step(ref, clock, ms, (red_far, blue_far), ball)
        ms += 8
    assert commands == [placed]
    blue_touch = robot(BLUE, 1, spot[0] + 0.1, spot[1], ball_contact=True)
    _step(ref, clock, ms, (red_far, blue_touch), ball)
    assert ref.gc.set_play is None and ref.ball_in_play
    assert ref.gc.robot(B1).warnings == 1
    kinds = [e.type for e in ref.events]
    assert "set_play_retaken" in kinds and "set_play_aborted" in kinds
