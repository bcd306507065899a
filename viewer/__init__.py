"""The web viewer of hlvs-runner: replays in 3D, live matches, MCAP export.

``viewer.api`` serves the pages and the replay / live API (``hlvs view``, and mounted into
``hlvs serve``); the front end is built from ``web/`` into ``viewer/static`` (committed, so
that installing the package needs no Node.js); ``viewer.mcap_export`` writes MCAP.
"""

from __future__ import annotations

from viewer.errors import ExportError, SourceError, ViewerError
from viewer.sources import Catalog, LiveSource, ReplaySource

__all__ = ["Catalog", "ExportError", "LiveSource", "ReplaySource", "SourceError", "ViewerError"]
