"""Applying the rules' decisions: GameController updates, world commands, log lines, events.

At most one game stoppage (goal, set play, dropped ball) is applied per step, the first in rule
order; removals and cards are all applied, each robot at most once.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

from contracts import FieldGeometry, Pose, RobotId, TeamColor
from referee.config import RefereeConfig
from referee.gamecontroller import Card, GameController, GameState, Penalty
from referee.logs import RefereeLog
from referee.rules import removal
from referee.rules.base import (
    AbortSetPlay,
    AwardSetPlay,
    BallInPlay,
    Decision,
    DropBall,
    GiveCard,
    Goal,
    PenalizeRobot,
    RetakeSetPlay,
)
from referee.snapshot import (
    PlaceBall,
    RefereeEvent,
    SetLimp,
    TeleportRobot,
    Vec2,
    WorldCommand,
    WorldSnapshot,
)

SETTLE_MS = 40  # 5 of the league's 8 ms steps (referee.py:1512, `player['stabilize'] = 5`)

PENALTY_NAMES = {
    Penalty.PICKUP_OR_INCAPABLE: "INCAPABLE",
    Penalty.PHYSICAL_CONTACT: "PHYSICAL_CONTACT",
    Penalty.BALL_MANIPULATION: "BALL_MANIPULATION",
}


@dataclass(slots=True)
class PenaltyBook:
    """The referee's records of the robots it removed, sent off or ignores."""

    limp: set[RobotId] = field(default_factory=set)  # made limp by a removal, not yet revived
    red_carded: set[RobotId] = field(default_factory=set)  # sent off for the rest of the game
    ignored: set[RobotId] = field(default_factory=set)  # in the world, not in the configuration
    carried: dict[RobotId, Vec2] = field(default_factory=dict)  # where each was last put
    # put there again, still, at that time (:data:`SETTLE_MS`)
    settling: dict[RobotId, tuple[int, Pose]] = field(default_factory=dict)

    def revive_all(self) -> list[WorldCommand]:
        """Every limp robot's limbs back, in the order of their names."""
        commands: list[WorldCommand] = [
            SetLimp(robot=r, limp=False) for r in sorted(self.limp, key=str)
        ]
        self.limp.clear()
        return commands

    def penalty_over(self, robot: RobotId) -> list[WorldCommand]:
        """``robot``'s penalty is over: its limbs back if it was limp."""
        if robot not in self.limp:
            return []
        self.limp.discard(robot)
        return [SetLimp(robot=robot, limp=False)]


class RefereeCore(Protocol):
    config: RefereeConfig
    field: FieldGeometry
    gc: GameController
    log: RefereeLog
    book: PenaltyBook
    ball_in_play: bool
    left_team: TeamColor
    set_play_spot: Vec2 | None  # where the set play in preparation placed the ball

    def emit(self, event: RefereeEvent) -> None: ...

    def ball_at(self, x_m: float, y_m: float) -> PlaceBall: ...

    def ball_away(self) -> PlaceBall: ...

    def state_event(self, snapshot: WorldSnapshot, what: str, **details: object) -> None: ...


def apply_decisions(
    ref: RefereeCore, decisions: list[Decision], snapshot: WorldSnapshot
) -> list[WorldCommand]:
    commands: list[WorldCommand] = []
    stopped = False
    occupied: list[Vec2] = [(r.position[0], r.position[1]) for r in snapshot.robots]
    for decision in decisions:
        if isinstance(decision, BallInPlay):
            _ball_in_play(ref, decision.reason, snapshot)
        elif isinstance(decision, PenalizeRobot):
            commands += penalize(ref, decision, snapshot, occupied)
        elif isinstance(decision, GiveCard):
            commands += _card(ref, decision, snapshot)
        elif stopped or ref.gc.state is not GameState.PLAYING:
            continue
        elif isinstance(decision, Goal):
            stopped = True
            commands += _goal(ref, decision, snapshot)
        elif isinstance(decision, AwardSetPlay):
            stopped = True
            commands += _set_play(ref, decision, snapshot)
        elif isinstance(decision, RetakeSetPlay | AbortSetPlay):
            stopped = True
            commands += _touched_set_play(ref, decision, snapshot)
        elif isinstance(decision, DropBall):
            stopped = True
            ref.gc.dropped_ball()
            ref.ball_in_play = False
            ref.log.info(snapshot.sim_time_ms, f"Dropped ball: {decision.reason}.")
            ref.emit(RefereeEvent(sim_time_ms=snapshot.sim_time_ms, type="dropped_ball",
                                  reason=decision.reason, placement=(0.0, 0.0, 0.0)))
            ref.state_event(snapshot, "READY")
            commands.append(ref.ball_at(0.0, 0.0))
    return commands


def _known(ref: RefereeCore, robot: RobotId, snapshot: WorldSnapshot) -> bool:
    """Robots of the world that the configuration does not list are not judged."""
    if robot.number in ref.gc.teams[robot.team].robots:
        return True
    if robot not in ref.book.ignored:
        ref.book.ignored.add(robot)
        ref.log.warning(
            snapshot.sim_time_ms, f"{robot} is not in the team configuration; ignored."
        )
    return False


def _goal(ref: RefereeCore, goal: Goal, snapshot: WorldSnapshot) -> list[WorldCommand]:
    defending = goal.scoring.opponent
    ref.gc.goal(goal.scoring)
    ref.ball_in_play = False
    by = f" by {goal.scorer}" if goal.scorer is not None else ""
    own = " (own goal)" if goal.own_goal else ""
    ref.log.info(snapshot.sim_time_ms, f"Score in {defending.value} goal{by}{own}")
    ref.emit(
        RefereeEvent(
            sim_time_ms=snapshot.sim_time_ms, type="goal", team=goal.scoring,
            player=goal.scorer.number if goal.scorer is not None else None,
            reason="own goal" if goal.own_goal else "goal",
            placement=snapshot.ball.position,
            details={
                "own_goal": goal.own_goal,
                "scorer_team": goal.scorer.team.value if goal.scorer is not None else None,
                "score": {"red": ref.gc.score(TeamColor.RED), "blue": ref.gc.score(TeamColor.BLUE)},
            },
        )
    )
    ref.state_event(snapshot, "READY")
    return [ref.ball_away()]


def _set_play(ref: RefereeCore, play: AwardSetPlay, snapshot: WorldSnapshot) -> list[WorldCommand]:
    ref.gc.begin_set_play(play.kind, play.team)
    ref.ball_in_play = False
    # the ball stays where it is through sub-phase 0 and is placed on this spot when it ends
    # (referee.placement), as the league's referee places it (hlvs_webots referee.py:2425-2430)
    ref.set_play_spot = x, y = play.position
    ref.log.info(
        snapshot.sim_time_ms,
        f"{play.kind.name} for the {play.team.value} team at ({x:.2f}, {y:.2f}): {play.reason}.",
    )
    ref.emit(
        RefereeEvent(
            sim_time_ms=snapshot.sim_time_ms, type=play.kind.name.lower(), team=play.team,
            reason=play.reason, placement=(x, y, ref.field.ball_radius_m),
        )
    )
    return []


def _ball_in_play(ref: RefereeCore, reason: str, snapshot: WorldSnapshot) -> None:
    if not ref.ball_in_play:
        ref.ball_in_play = True
        ref.log.info(snapshot.sim_time_ms, f"Ball in play: {reason}.")
        ref.emit(RefereeEvent(sim_time_ms=snapshot.sim_time_ms, type="ball_in_play",
                              reason=reason))  # fmt: skip


def _touched_set_play(
    ref: RefereeCore, decision: RetakeSetPlay | AbortSetPlay, snapshot: WorldSnapshot
) -> list[WorldCommand]:
    """The ball touched before the set play was taken: RETAKE (sub-phase 0 again, at whose end
    the ball is placed again, hlvs_webots referee.py:1366-1372) or ABORT (the ball in play)."""
    play = ref.gc.set_play
    if play is None:
        return []
    now = snapshot.sim_time_ms
    what = "RETAKE" if isinstance(decision, RetakeSetPlay) else "ABORT"
    ref.log.info(now, f"{play.kind.name} for {play.team.value}: {what}, {decision.robot} "
                 f"{decision.reason}.")  # fmt: skip
    if isinstance(decision, AbortSetPlay):
        ref.gc.abort_set_play()
        ref.set_play_spot = None
        ref.emit(RefereeEvent(sim_time_ms=now, type="set_play_aborted", team=play.team,
                              player=decision.robot.number, reason=decision.reason))  # fmt: skip
        _ball_in_play(ref, f"{play.kind.name.lower()} aborted", snapshot)
        return []
    ref.gc.retake_set_play()
    if ref.set_play_spot is None:
        ref.set_play_spot = (snapshot.ball.position[0], snapshot.ball.position[1])
    x, y = ref.set_play_spot
    ref.emit(
        RefereeEvent(
            sim_time_ms=now, type="set_play_retaken", team=play.team,
            player=decision.robot.number, reason=decision.reason,
            placement=(x, y, ref.field.ball_radius_m),
        )
    )  # fmt: skip
    return []


def reentry_pose(
    ref: RefereeCore, robot: RobotId, snapshot: WorldSnapshot, occupied: list[Vec2]
) -> Pose:
    """Where a removed robot is put: its team file's re-entry pose, on the side away from the
    ball, clear of the ``occupied`` spots (:func:`referee.rules.removal.reentry_pose`)."""
    player = ref.config.team(robot.team).player(robot.number)
    return removal.reentry_pose(
        template=player.reentry_pose,
        side_sign=-1.0 if robot.team is ref.left_team else 1.0,
        ball_y_m=snapshot.ball.position[1],
        occupied=occupied,
        field=ref.field,
    )


def penalize(
    ref: RefereeCore, decision: PenalizeRobot, snapshot: WorldSnapshot, occupied: list[Vec2]
) -> list[WorldCommand]:
    robot = decision.robot
    if not _known(ref, robot, snapshot):
        return []
    info = ref.gc.robot(robot)
    if info.penalty is not Penalty.NONE or robot in ref.book.red_carded:
        return []
    ref.gc.penalize(robot, decision.penalty)
    others = [r.position for r in snapshot.robots if r.id != robot]
    taken = [(p[0], p[1]) for p in others] + occupied[len(snapshot.robots) :]
    pose = reentry_pose(ref, robot, snapshot, taken)
    occupied.append((pose.x_m, pose.y_m))
    ref.book.carried[robot] = (pose.x_m, pose.y_m)
    ref.book.settling[robot] = (snapshot.sim_time_ms + SETTLE_MS, pose)
    ref.book.limp.add(robot)
    name = PENALTY_NAMES.get(decision.penalty, decision.penalty.name)
    ref.log.info(snapshot.sim_time_ms, f"{name} penalty for {robot}: {decision.reason}.")
    ref.emit(
        RefereeEvent(
            sim_time_ms=snapshot.sim_time_ms, type="penalty", team=robot.team,
            player=robot.number, reason=decision.reason,
            placement=(pose.x_m, pose.y_m, 0.0),
            details={"penalty": decision.penalty.name, "code": int(decision.penalty),
                     "seconds": ref.config.timing.removal_penalty_s},
        )
    )
    return removal.removal_commands(robot, pose)


def _card(ref: RefereeCore, decision: GiveCard, snapshot: WorldSnapshot) -> list[WorldCommand]:
    robot = decision.robot
    if robot in ref.book.red_carded or not _known(ref, robot, snapshot):
        return []
    given = ref.gc.card(robot, decision.card)
    ref.log.info(snapshot.sim_time_ms, f"{given.value.capitalize()} card for {robot}: "
                 f"{decision.reason}.")
    ref.emit(
        RefereeEvent(
            sim_time_ms=snapshot.sim_time_ms, type="card", team=robot.team, player=robot.number,
            reason=decision.reason, details={"card": given.value},
        )
    )
    if given is not Card.RED:
        return []
    ref.book.red_carded.add(robot)
    ref.book.limp.discard(robot)
    return removal.red_card_commands(robot)


def penalised_robots(
    ref: RefereeCore, snapshot: WorldSnapshot, before: frozenset[RobotId]
) -> list[WorldCommand]:
    """Every step, in and out of the shoot-out: a robot the referee removed is put on its spot
    again, still, :data:`SETTLE_MS` later, as the league's referee ``stabilize``s a robot it put
    somewhere 5 steps later (hlvs_webots referee.py:1512-1514, 1460-1474, every step 2117):
    whatever pushed it meanwhile (a collision, a velocity set on it) is undone; then penalised
    robots (``before`` this step and still) back on the field are judged (2436-2438)."""
    commands: list[WorldCommand] = []
    now = snapshot.sim_time_ms
    for robot, (due_ms, pose) in list(ref.book.settling.items()):
        if now < due_ms:
            continue
        del ref.book.settling[robot]
        if ref.gc.robot(robot).penalty is not Penalty.NONE and robot not in ref.book.red_carded:
            commands.append(TeleportRobot(robot=robot, pose=pose))
    still = before & frozenset(ref.gc.penalised())
    for robot in removal.penalised_in_field(snapshot, still, ref.field, ref.book.carried):
        commands += penalised_back_in_field(ref, robot, snapshot)
    return commands


def penalised_back_in_field(
    ref: RefereeCore, robot: RobotId, snapshot: WorldSnapshot
) -> list[WorldCommand]:
    """A penalised robot back on the field: a yellow card (a second one is a red card, which
    sends it off), else it is removed again with its penalty time counted anew, as the league's
    referee sends the penalty again (hlvs_webots referee.py:1297-1299, 1435-1454). It sends the
    penalty after a second yellow card too: the robot sent off carries a new INCAPABLE penalty
    (34), not SUBSTITUTE, in the GameController's packet (1438-1448)."""
    reason = "penalised robot re-entered the field"
    commands = _card(ref, GiveCard(robot, Card.YELLOW, reason), snapshot)
    if robot in ref.book.red_carded:
        ref.gc.penalize(robot, Penalty.PICKUP_OR_INCAPABLE)
        return commands
    ref.gc.unpenalize(robot)
    occupied = [(r.position[0], r.position[1]) for r in snapshot.robots]
    decision = PenalizeRobot(robot, Penalty.PICKUP_OR_INCAPABLE, reason)
    return commands + penalize(ref, decision, snapshot, occupied)
