"""The ladder's pages inside ``hlvs serve``: ``/watch/ladder`` (the table, best rating first) and
``/watch/ladder/<team>`` (the team's rating history and its rated matches, with links to the
replays of friendlies).

They are pages of the viewer's front end (``web/src/pages/ladder.ts``), filled in the browser
from ``/v1/ladder`` with the token of the browser session, under the same navigation bar, sign-in
and sign-out as every other page; an error is shown as a sentence, never as the raw answer.
Mounted by ``hlvs.app`` before the viewer.
"""

from __future__ import annotations

from fastapi import APIRouter, FastAPI
from fastapi.responses import FileResponse

from viewer.api import STATIC

router = APIRouter()


@router.get("/watch/ladder", include_in_schema=False)
@router.get("/watch/ladder/{team}", include_in_schema=False)
def ladder_page() -> FileResponse:
    return FileResponse(STATIC / "index.html")


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
