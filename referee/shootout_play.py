"""The penalty shoot-out played through the GameController: each kick set up in SET, SET timed,
the kick's outcome judged and counted, the next kick set up, until one decides the game.

:class:`ShootoutPlay` drives a :class:`~referee.shootout.Shootout` (where the robots and the
ball stand, the goalkeeper's line, a kick's outcome); it reads and changes the game through
:class:`ShootoutHost`, the part of the referee it needs.
"""

from __future__ import annotations

from typing import Protocol

from contracts import RobotId, TeamColor
from referee.config import RefereeConfig
from referee.gamecontroller import GameController, GameState
from referee.judgement import PenaltyBook
from referee.logs import RefereeLog
from referee.rules.base import Decision
from referee.shootout import KickOutcome, Shootout
from referee.snapshot import RefereeEvent, WorldCommand, WorldSnapshot


class ShootoutHost(Protocol):
    config: RefereeConfig
    gc: GameController
    log: RefereeLog
    book: PenaltyBook
    left_team: TeamColor
    set_since_ms: int | None  # when the GameController entered SET (None: not in SET)

    def emit(self, event: RefereeEvent) -> None: ...

    def state_event(self, snapshot: WorldSnapshot, what: str, **details: object) -> None: ...

    def apply(self, decisions: list[Decision], snapshot: WorldSnapshot) -> list[WorldCommand]: ...

    def finish(self, snapshot: WorldSnapshot, winner: TeamColor | None, *,
               coin_toss: bool = False) -> None: ...  # fmt: skip


class ShootoutPlay:
    def __init__(self, host: ShootoutHost) -> None:
        self._host = host
        self.shootout = Shootout(
            config=host.config, first=host.config.kickoff, left=host.left_team
        )

    def begin(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        self._host.log.info(snapshot.sim_time_ms, "Penalty shoot-out begins.")
        return self._setup_kick(snapshot)

    def step(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        host = self._host
        gc = host.gc
        shootout = self.shootout
        now = snapshot.sim_time_ms
        commands: list[WorldCommand] = []
        if gc.state in (GameState.SET, GameState.PLAYING):
            penalized = set(gc.penalised())
            decisions = shootout.judge_goalkeeper(snapshot, penalized=penalized)
            commands += host.apply(list(decisions), snapshot)
        if gc.state is GameState.SET and host.set_since_ms is not None:
            if now - host.set_since_ms >= host.config.timing.shootout_set_to_play_s * 1000.0:
                gc.transition(GameState.PLAYING)
                host.set_since_ms = None
                host.state_event(snapshot, "PLAYING")
            return commands
        if gc.state is not GameState.PLAYING:
            return commands
        outcome = shootout.judge(snapshot, gc.secs_remaining)
        if outcome is None:
            return commands
        if self._record_kick(snapshot, outcome):
            return []
        shootout.attacker = shootout.attacker.opponent
        return commands + self._setup_kick(snapshot)

    def _setup_kick(self, snapshot: WorldSnapshot) -> list[WorldCommand]:
        """SET for the next kick. A team with no player to kick loses its turn at once, as
        the league's referee skips it (``next_penalty_shootout``, hlvs_webots referee.py:
        1648-1654): the kick counts as missed and the other team's kick is set up in the
        same SET."""
        host = self._host
        gc = host.gc
        shootout = self.shootout
        while True:
            keeper = gc.goalkeeper(shootout.attacker.opponent)
            placing = shootout.setup_kick(snapshot, host.book.red_carded, keeper=keeper)
            if shootout.kicker is not None:
                break
            skipped = KickOutcome(
                shootout.attacker, RobotId(shootout.attacker, 0), False, "no kicker"
            )
            if self._record_kick(snapshot, skipped):
                return []
            shootout.attacker = shootout.attacker.opponent
        host.left_team = shootout.left_team
        gc.kickoff_team = shootout.attacker
        gc.secs_remaining = host.config.timing.shootout_kick_s
        gc.transition(GameState.SET)
        host.set_since_ms = snapshot.sim_time_ms
        # the league's GameController has been FINISHED between the kicks (after a goal, or
        # sent by its referee, hlvs_webots referee.py:1636-1638), which clears every penalty
        for robot in gc.penalised():
            gc.unpenalize(robot)
        commands = host.book.revive_all() + placing
        host.state_event(snapshot, "SET", kicker=str(shootout.kicker))
        return commands

    def _record_kick(self, snapshot: WorldSnapshot, outcome: KickOutcome) -> bool:
        """Count a kick; True when it decided the shoot-out (the game is then over)."""
        host = self._host
        gc = host.gc
        now = snapshot.sim_time_ms
        status = self.shootout.record(gc, outcome, seed=host.config.seed)
        kicks = gc.teams[outcome.team].penalty_shots
        verdict = "scored" if outcome.scored else f"missed ({outcome.reason})"
        host.log.info(now, f"Penalty shoot-out: {outcome.kicker} kick {kicks} {verdict}.")
        host.emit(
            RefereeEvent(
                sim_time_ms=now, type="shootout_kick", team=outcome.team,
                player=outcome.kicker.number, reason=outcome.reason,
                details={"scored": outcome.scored, "kick": kicks},
            )
        )
        if not status.decided:
            return False
        if gc.state is not GameState.FINISHED:
            gc.transition(GameState.FINISHED)
        host.finish(snapshot, status.winner, coin_toss=status.coin_toss)
        return True
