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
    from tournament.export import export_document, write_csv
    from tournament.notify import (
        NotifySettings,
        Outbox,
        Webhook,
        recorded_settings,
        scheduler_state,
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
    "Ledger",
    "LiveGame",
    "MatchContext",
    "MatchResultRecord",
    "MatchRow",
    "MatchServices",
    "NotifySettings",
    "OperatorRequest",
    "Outbox",
    "PlayOutcome",
    "STOPPING",
    "ScheduledMatchState",
    "Snapshot",
    "Standing",
    "TournamentServices",
    "Webhook",
    "abort",
    "apply_file",
    "export_document",
    "file_differences",
    "init_state",
    "match_folder",
    "read_outcome",
    "recorded_schedule",
    "recorded_settings",
    "recover_interrupted",
    "replay_path",
    "reschedule",
    "run_schedule",
    "scheduler_state",
    "standings",
    "status_lines",
    "tournament_overview",
    "write_csv",
    "write_game_file",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "tournament.controls": (
            "DEFAULT_ABORT_GRACE_S", "abort", "apply_file", "file_differences", "recorded_schedule",
            "reschedule",
        ),
        "tournament.export": ("export_document", "write_csv"),
        "tournament.notify": (
            "NotifySettings", "Outbox", "Webhook", "recorded_settings", "scheduler_state",
        ),
        "tournament.overview": (
            "Snapshot", "match_folder", "replay_path", "status_lines", "tournament_overview",
        ),
    })
