"""What the referee reports: the telemetry state dict, the match result, STATUS lines, who
touched the ball."""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence

from contracts import GameStateRecord, PenaltyRecord, PlayRecord, RobotId, TeamColor, to_data
from referee.clock import Clock
from referee.gamecontroller import GameController
from referee.gamecontroller.machine import wire_seconds
from referee.snapshot import RefereeEvent, WorldSnapshot

COLORS = (TeamColor.RED, TeamColor.BLUE)


def score(gc: GameController) -> dict[str, int]:
    return {color.value: gc.score(color) for color in COLORS}


def game_state(gc: GameController, *, left_team: TeamColor, waiting: bool) -> GameStateRecord:
    """The state dict of the telemetry contract (plus set play, phase, kick-off, sides)."""
    penalties: dict[str, PenaltyRecord] = {
        f"{robot.team.value}-{robot.number}": {
            "penalty": gc.robot(robot).penalty.name,
            "secs_till_unpenalised": wire_seconds(gc.robot(robot).left_ms),
        }
        for robot in gc.penalised()
    }
    play = gc.set_play
    return {
        "state": gc.state.name,
        "secondary_state": gc.secondary_state.name,
        "set_play": None
        if play is None
        else {"team": play.team.value, "sub_phase": play.sub_phase},
        "half": gc.half,
        "phase": gc.phase.name,
        "secs_remaining": gc.wire_secs_remaining(),
        "kickoff": gc.kickoff_team.value if gc.kickoff_team is not None else "dropped_ball",
        "left_team": left_team.value,
        "score": score(gc),
        "penalties": penalties,
        "waiting_for_wall_clock": waiting,
    }


def result(
    gc: GameController,
    events: Sequence[RefereeEvent],
    *,
    finished: bool,
    winner: TeamColor | None,
    shootout: bool,
    coin_toss: bool,
    play: PlayRecord,
) -> dict[str, object]:
    """``winner`` is ``"red"``, ``"blue"``, ``"draw"`` or None while the game is not over."""
    summary = Counter(event.type for event in events)
    out: dict[str, object] = {
        "state": gc.state.name,
        "score": score(gc),
        "winner": (winner.value if winner is not None else "draw") if finished else None,
        "events_summary": dict(sorted(summary.items())),
        "play": to_data(play),
    }
    if shootout:
        out["shootout"] = {
            color.value: {
                "kicks": gc.teams[color].penalty_shots,
                "scored": bin(gc.teams[color].single_shots).count("1"),
            }
            for color in COLORS
        }
        out["coin_toss"] = coin_toss
    return out


class StatusReporter:
    """STATUS lines (speed factor, state, remaining time) every ``period_s`` of wall time."""

    def __init__(self, *, clock: Clock, period_s: float) -> None:
        self._clock = clock
        self._period_s = period_s
        self._real_s = clock.monotonic()
        self._sim_ms = 0

    def lines(self, gc: GameController, sim_time_ms: int) -> list[str]:
        real = self._clock.monotonic()
        elapsed = real - self._real_s
        if elapsed < self._period_s or elapsed <= 0:
            return []
        factor = (sim_time_ms - self._sim_ms) / 1000.0 / elapsed
        self._real_s, self._sim_ms = real, sim_time_ms
        return [
            f"STATUS: Avg speed factor: {factor:.3f} (over last {elapsed:.2f} seconds)",
            f"STATUS: state: STATE_{gc.state.name}, remaining time: "
            f"{gc.wire_secs_remaining()}",
        ]


class TouchReporter:
    """A line for each new toucher of the ball (a robot touching it again after another)."""

    def __init__(self) -> None:
        self._last_toucher: RobotId | None = None
        self._last_touch_ms: int | None = None

    def line(self, snapshot: WorldSnapshot) -> str | None:
        toucher = snapshot.last_ball_toucher
        if toucher is None or snapshot.last_ball_touch_ms == self._last_touch_ms:
            return None
        new = toucher != self._last_toucher or self._last_touch_ms is None
        self._last_toucher = toucher
        self._last_touch_ms = snapshot.last_ball_touch_ms
        return f"Ball touched by {toucher}." if new else None


def game_over(
    gc: GameController, winner: TeamColor | None, *, coin_toss: bool, sim_time_ms: int
) -> tuple[list[str], RefereeEvent]:
    """The log lines (final score, winner or draw) and the ``game_over`` event of the end."""
    red, blue = gc.score(TeamColor.RED), gc.score(TeamColor.BLUE)
    lines = [f"FINAL SCORE: {red}-{blue}"]
    if winner is None:
        lines.append("The game ended in a draw.")
    else:
        lines.append(f"The winner is the {winner.value} team.")
    event = RefereeEvent(
        sim_time_ms=sim_time_ms, type="game_over", team=winner,
        reason="draw" if winner is None else "winner",
        details={"score": {"red": red, "blue": blue}, "coin_toss": coin_toss},
    )
    return lines, event
