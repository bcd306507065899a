"""The GameController's state as an ``RGme`` datagram."""

from __future__ import annotations

import math

from contracts import MAX_PLAYERS, GameControlData, GameType, RobotInfo, TeamColor, TeamInfo
from referee.gamecontroller.machine import GameController
from referee.gamecontroller.states import DROPBALL_TEAM, GameTypeCode, TeamColourCode


def _seconds(value: float, low: int, high: int) -> int:
    return max(low, min(high, math.ceil(value)))


def _team(gc: GameController, color: TeamColor, number: int) -> TeamInfo:
    team = gc.teams[color]
    players = []
    for n in range(1, MAX_PLAYERS + 1):
        info = team.robots.get(n)
        if info is None:
            players.append(RobotInfo())
            continue
        players.append(
            RobotInfo(
                penalty=int(info.penalty),
                secs_till_unpenalised=_seconds(info.secs_till_unpenalised, 0, 255),
                number_of_warnings=min(info.warnings, 255),
                yellow_card_count=min(info.yellow_cards, 255),
                red_card_count=min(info.red_cards, 255),
                goal_keeper=info.goalkeeper,
            )
        )
    colour = TeamColourCode.RED if color is TeamColor.RED else TeamColourCode.BLUE
    return TeamInfo(
        team_number=number,
        team_colour=int(colour),
        score=min(team.score, 255),
        penalty_shot=min(team.penalty_shots, 255),
        single_shots=team.single_shots & 0xFFFF,
        players=tuple(players),
    )


def game_control_data(
    gc: GameController,
    *,
    team_numbers: dict[TeamColor, int],
    players_per_team: int,
    packet_number: int,
    left_team: TeamColor,
) -> GameControlData:
    """The ``RGme`` content of ``gc``, ordered as the league's GameController orders it.

    ``teams[0]`` is the team playing on the left (``left_team``) and ``teams[1]`` the other; the
    two entries swap when the sides change at half time, and robots find their own entry by
    ``teamNumber``.
    """
    kickoff = DROPBALL_TEAM if gc.kickoff_team is None else team_numbers[gc.kickoff_team]
    info = (0, 0, 0, 0)
    if gc.set_play is not None:
        info = (team_numbers[gc.set_play.team], gc.set_play.sub_phase, 0, 0)
    order = (left_team, left_team.opponent)
    game_type = GameTypeCode.ROUNDROBIN if gc.game_type is GameType.NORMAL else GameTypeCode.PLAYOFF
    return GameControlData(
        packet_number=packet_number & 0xFF,
        players_per_team=players_per_team,
        game_type=int(game_type),
        state=int(gc.state),
        first_half=gc.half == 1,
        kick_off_team=kickoff,
        secondary_state=int(gc.secondary_state),
        secondary_state_info=info,
        secs_remaining=_seconds(gc.secs_remaining, -32768, 32767),
        secondary_time=_seconds(gc.secondary_time, -32768, 32767),
        teams=(
            _team(gc, order[0], team_numbers[order[0]]),
            _team(gc, order[1], team_numbers[order[1]]),
        ),
    )
