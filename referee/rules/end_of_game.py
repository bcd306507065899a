"""End of a period and of the game: what follows, and who won.

NORMAL: two halves, a draw stands. KNOCKOUT: a draw after the second half gives two overtime
halves, a draw after those a penalty shoot-out. PENALTY games are only a shoot-out. Shoot-out:
5 kicks per team, decided as soon as one team cannot catch up; still level after 5 each, it
continues kick for kick ("extended") until a pair of kicks separates the teams, at most
``max_kicks`` each; still level then, a seeded coin toss decides.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from enum import StrEnum

from contracts import GameType, TeamColor
from referee.gamecontroller.states import SecondaryState

REGULATION_KICKS = 5
MAX_KICKS = 10


class Next(StrEnum):
    SECOND_HALF = "second half"
    OVERTIME = "overtime"
    OVERTIME_SECOND_HALF = "overtime second half"
    SHOOTOUT = "penalty shoot-out"
    FINISHED = "finished"


def after_period(
    *, game_type: GameType, phase: SecondaryState, half: int, score: dict[TeamColor, int]
) -> Next:
    draw = score[TeamColor.RED] == score[TeamColor.BLUE]
    if phase is SecondaryState.NORMAL:
        if half == 1:
            return Next.SECOND_HALF
        return Next.OVERTIME if draw and game_type is GameType.KNOCKOUT else Next.FINISHED
    if phase is SecondaryState.OVERTIME:
        if half == 1:
            return Next.OVERTIME_SECOND_HALF
        return Next.SHOOTOUT if draw else Next.FINISHED
    return Next.FINISHED


def winner(score: dict[TeamColor, int]) -> TeamColor | None:
    red, blue = score[TeamColor.RED], score[TeamColor.BLUE]
    if red == blue:
        return None
    return TeamColor.RED if red > blue else TeamColor.BLUE


@dataclass(frozen=True, slots=True)
class ShootoutStatus:
    decided: bool
    winner: TeamColor | None = None
    coin_toss: bool = False


def shootout_status(
    *,
    taken: dict[TeamColor, int],
    scored: dict[TeamColor, int],
    seed: int = 0,
    regulation: int = REGULATION_KICKS,
    max_kicks: int = MAX_KICKS,
) -> ShootoutStatus:
    red, blue = TeamColor.RED, TeamColor.BLUE
    if taken[red] <= regulation and taken[blue] <= regulation:
        left_red, left_blue = regulation - taken[red], regulation - taken[blue]
        if scored[red] > scored[blue] + left_blue:
            return ShootoutStatus(True, red)
        if scored[blue] > scored[red] + left_red:
            return ShootoutStatus(True, blue)
        if left_red or left_blue:
            return ShootoutStatus(False)
    if taken[red] != taken[blue]:
        return ShootoutStatus(False)
    if scored[red] != scored[blue]:
        return ShootoutStatus(True, red if scored[red] > scored[blue] else blue)
    if taken[red] < max_kicks:
        return ShootoutStatus(False)
    return ShootoutStatus(True, random.Random(seed).choice((red, blue)), coin_toss=True)
