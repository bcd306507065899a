"""Tournament scheduling: pull, play and deliver every match on time, across restarts."""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from tournament.jobs import STOPPING
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

if TYPE_CHECKING:
    from tournament.controls import (
        DEFAULT_ABORT_GRACE_S,
        abort,
        apply_file,
        file_differences,
        recorded_schedule,
        reschedule,
    )
    from tournament.overview import (
        Snapshot,
        match_folder,
        replay_path,
        status_lines,
        tournament_overview,
    )

__all__ = [
    "DEFAULT_ABORT_GRACE_S",
    "STOPPING",
    "Ledger",
    "LiveGame",
    "MatchContext",
    "MatchResultRecord",
    "MatchRow",
    "MatchServices",
    "OperatorRequest",
    "PlayOutcome",
    "ScheduledMatchState",
    "Snapshot",
    "Standing",
    "TournamentServices",
    "abort",
    "apply_file",
    "file_differences",
    "init_state",
    "match_folder",
    "read_outcome",
    "recorded_schedule",
    "recover_interrupted",
    "replay_path",
    "reschedule",
    "run_schedule",
    "standings",
    "status_lines",
    "tournament_overview",
    "write_game_file",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "tournament.controls": (
            "DEFAULT_ABORT_GRACE_S", "abort", "apply_file", "file_differences", "recorded_schedule",
            "reschedule",
        ),
        "tournament.overview": (
            "Snapshot", "match_folder", "replay_path", "status_lines", "tournament_overview",
        ),
    })
