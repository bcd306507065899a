"""The submission service as ``hlvs serve`` serves it: the service's API (with the HTTP
environment API) and the web pages of :mod:`viewer.service_pages` mounted.

The service does not know the pages: they sit above it and hand their ``mount`` here.
"""

from __future__ import annotations

from typing import Any

from fastapi import FastAPI

from service import Settings
from service import create_app as create_service_app
from viewer import api_docs, ladder_page, service_pages, tournament_pages

MOUNTS = (  # the ladder before the viewer's /watch/*
    ladder_page.mount,
    service_pages.mount,
    tournament_pages.mount,  # the tournament's overview, replays and live views (operators)
    api_docs.mount,  # /docs from the package's Swagger UI (no CDN)
)


def create_app(settings: Settings, **options: Any) -> FastAPI:
    """The whole app; ``options`` are those of :func:`service.app.create_app`
    (``pool_factory``, ``preflight``, ``start_worker``)."""
    return create_service_app(settings, mounts=MOUNTS, **options)


__all__ = ["MOUNTS", "create_app"]
