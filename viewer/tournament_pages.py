"""The tournament inside ``hlvs serve``, for operators: ``GET /v1/operator/tournament``
(every match with its state, score, live clock, log states and links; the standings with their
tie-breaks; the knockout bracket) and the replays and live views of the tournament's matches
under ``/api/tournament`` (the viewer's API; the pages are ``/watch/tournament``,
``/watch/tournament/live/<match>`` and ``/watch/tournament/replay/<match>``). Read from the
schedule's state file (``HLVS_SERVICE_SCHEDULE_STATE``). Operator tokens only."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from fastapi import APIRouter, FastAPI, Request
from pydantic import BaseModel

from service import NotFound, OperatorPrincipal, get_services
from viewer.api import build_router
from viewer.sources import LiveSource, ReplaySource, Teams, live_of

if TYPE_CHECKING:
    from tournament import LiveGame

router = APIRouter(prefix="/v1/operator", tags=["operator"])
VIEWER_PREFIX = "/api/tournament"
SNAPSHOT_TIMEOUT_S = 1.0


class TournamentView(BaseModel):
    name: str
    updated_at: str
    matches: list[dict[str, Any]]
    standings: list[dict[str, Any]]
    bracket: list[list[str]]
    scheduler: dict[str, Any] | None = None  # running, since (its last heartbeat), text
    warnings: list[str]


def _ledger(request: Request) -> Any:
    from tournament import Ledger

    state = get_services(request).settings.schedule_state
    if not state or not Path(state).is_file():
        raise NotFound(what="tournament schedule state",
                       ident=state or "(HLVS_SERVICE_SCHEDULE_STATE is not set)")
    return Ledger(Path(state))


def snapshot(folder: Path) -> LiveGame | None:
    """A running match's score and clock (replaced in tests)."""
    from viewer.snapshot import game_snapshot

    return game_snapshot(folder, timeout_s=SNAPSHOT_TIMEOUT_S)


@router.get("/tournament")
def get_tournament(request: Request, principal: OperatorPrincipal) -> TournamentView:
    from tournament import tournament_overview

    return TournamentView(**tournament_overview(_ledger(request), snapshot=lambda f: snapshot(f)))


def _folder(request: Request, match_id: str) -> tuple[Any, Path]:
    from tournament import match_folder

    ledger = _ledger(request)
    try:
        row = ledger.row(match_id)
    except KeyError:
        raise NotFound(what="tournament match", ident=match_id) from None
    return row, match_folder(ledger, match_id)


class TournamentResolver:
    """The viewer's sources for the tournament's matches, for operators."""

    def replay(self, replay_id: str, request: Request,
               principal: OperatorPrincipal) -> ReplaySource:
        from contracts import files
        from tournament import replay_path

        row, folder = _folder(request, replay_id)
        path = replay_path(folder)
        if path is None:
            raise NotFound(what="replay of tournament match", ident=f"{row.id} ({row.state})")
        stats = path.with_name(files.API_STATS)
        return ReplaySource(id=row.id, path=path, stats_path=stats if stats.is_file() else None,
                            teams=Teams(red=row.red, blue=row.blue))

    def live(self, match_id: str, request: Request, principal: OperatorPrincipal) -> LiveSource:
        row, folder = _folder(request, match_id)
        live = live_of(folder, id=row.id) if row.state.value == "PLAYING" else None
        if live is None:
            raise NotFound(what="running tournament match", ident=f"{row.id} ({row.state})")
        return replace(live, teams=Teams(red=row.red, blue=row.blue))

    def listing(self, request: Request, principal: OperatorPrincipal
                ) -> tuple[list[ReplaySource], list[LiveSource]]:
        return [], []


def mount(app: FastAPI) -> None:
    app.include_router(router)
    app.include_router(build_router(TournamentResolver(), prefix=VIEWER_PREFIX, pages=False))
