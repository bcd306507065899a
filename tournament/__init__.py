"""Tournament scheduling: pull, play and deliver every match on time, across restarts."""

from __future__ import annotations

from tournament.overview import LiveGame
from tournament.runner import init_state, recover_interrupted, run_schedule
from tournament.services import (
    MatchContext,
    MatchServices,
    PlayOutcome,
    TournamentServices,
    read_outcome,
    write_game_file,
)
from tournament.standings import Standing, standings
from tournament.state import (
    Ledger,
    MatchResultRecord,
    MatchRow,
    OperatorRequest,
    ScheduledMatchState,
)

__all__ = [
    "Ledger",
    "LiveGame",
    "MatchContext",
    "MatchResultRecord",
    "MatchRow",
    "MatchServices",
    "OperatorRequest",
    "ScheduledMatchState",
    "PlayOutcome",
    "Standing",
    "TournamentServices",
    "init_state",
    "read_outcome",
    "recover_interrupted",
    "run_schedule",
    "standings",
    "write_game_file",
]
