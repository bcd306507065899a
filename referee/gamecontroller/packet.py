"""The GameController's state as an ``RGme`` datagram."""

from __future__ import annotations

from contracts import (
    MAX_PLAYERS,
    FieldClass,
    GameControlData,
    GameType,
    RobotInfo,
    TeamColor,
    TeamInfo,
)
from referee.gamecontroller.machine import GameController, wire_seconds
from referee.gamecontroller.states import DROPBALL_TEAM, GameTypeCode, Penalty, TeamColourCode

LEAGUE_PLAYERS_PER_TEAM: dict[FieldClass, int] = {FieldClass.KID: 4, FieldClass.ADULT: 2}
"""``playersPerTeam`` as the league's GameController sends it: its rules' ``teamSize``
(``GameControlData.java:62``), 4 for ``HLSimulationKid`` (``HLSimulationKid.java:17``) and 2 for
``HLSimulationAdult`` (``HLSimulationAdult.java:17``). Every player slot from this number on
carries the penalty SUBSTITUTE (``AdvancedData.java:143-146``, ``robotsPlaying``, the same
numbers)."""


def _clamp(value: int, low: int, high: int) -> int:
    return max(low, min(high, value))


def _team(gc: GameController, color: TeamColor, number: int, players_per_team: int) -> TeamInfo:
    team = gc.teams[color]
    players = []
    for n in range(1, MAX_PLAYERS + 1):
        info = team.robots.get(n)
        if info is None:
            # AdvancedData.java:144: the slots past the league's robotsPlaying are substitutes
            substitute = n > players_per_team
            players.append(RobotInfo(penalty=int(Penalty.SUBSTITUTE) if substitute else 0))
            continue
        players.append(
            RobotInfo(
                penalty=int(info.penalty),
                secs_till_unpenalised=_clamp(wire_seconds(info.left_ms), 0, 255),
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
    ``teamNumber``. ``players_per_team`` is the league's (:data:`LEAGUE_PLAYERS_PER_TEAM`): the
    empty slots past it carry SUBSTITUTE; a robot of the match keeps its own status in any slot.
    The times are the league's, exact (:meth:`GameController.wire_secs_remaining`,
    :meth:`GameController.wire_secondary_time`).
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
        secs_remaining=_clamp(gc.wire_secs_remaining(), -32768, 32767),
        secondary_time=_clamp(gc.wire_secondary_time(), -32768, 32767),
        teams=(
            _team(gc, order[0], team_numbers[order[0]], players_per_team),
            _team(gc, order[1], team_numbers[order[1]], players_per_team),
        ),
    )
