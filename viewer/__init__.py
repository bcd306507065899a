"""The web viewer of hlvs-runner: replays in 3D, live matches, MCAP export.

``viewer.api`` serves the pages and the replay / live API (``hlvs view``, and mounted into
``hlvs serve``); the front end is built from ``web/`` into ``viewer/static`` (committed, so
that installing the package needs no Node.js); ``viewer.mcap_export`` writes MCAP.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports
from viewer.errors import ExportError, SourceError, ViewerError
from viewer.sources import Catalog, LiveSource, ReplaySource

if TYPE_CHECKING:
    from viewer import api_docs, ladder_page, service_pages, tournament_pages
    from viewer.cli import export, view
    from viewer.snapshot import game_snapshot

__all__ = [
    "Catalog",
    "ExportError",
    "LiveSource",
    "ReplaySource",
    "SourceError",
    "ViewerError",
    "api_docs",
    "export",
    "game_snapshot",
    "ladder_page",
    "service_pages",
    "tournament_pages",
    "view",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "viewer": ("api_docs", "ladder_page", "service_pages", "tournament_pages"),
        "viewer.cli": ("export", "view"),
        "viewer.snapshot": ("game_snapshot",),
    })
