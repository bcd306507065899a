"""The league's submission service (``hlvs serve``): teams, tokens, team files, test matches.

Public surface: :func:`create_app` and :class:`Settings` to build the app; ``require_team`` /
``require_operator`` (FastAPI dependencies) and :class:`Principal` for routers of other
packages; :class:`MatchPool` is the port a cluster implements to play matches.

The names are imported on first use, so that ``hlvs --help`` (which reads
``hlvs.commands.service``) does not import FastAPI and SQLAlchemy.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from contracts import lazy_exports

if TYPE_CHECKING:
    from service import tokens
    from service.accounts import ensure_team_account
    from service.admin import add_team, list_tokens
    from service.app import create_app, open_storage, pool_from_settings
    from service.deps import (
        DbSession,
        OperatorPrincipal,
        TeamPrincipal,
        get_db,
        get_services,
        require_operator,
        require_team,
        require_token,
    )
    from service.errors import ClientError, InvalidInput, NotFound, ServiceError
    from service.results import stored_many
    from service.services import Services
    from service.settings import Settings, open_data_dir, open_database
    from service.tokens import Principal
    from service.views import SubmissionReport

__all__ = [
    "ClientError",
    "DbSession",
    "InvalidInput",
    "NotFound",
    "OperatorPrincipal",
    "Principal",
    "ServiceError",
    "Services",
    "Settings",
    "SubmissionReport",
    "TeamPrincipal",
    "add_team",
    "create_app",
    "ensure_team_account",
    "get_db",
    "get_services",
    "list_tokens",
    "open_data_dir",
    "open_database",
    "open_storage",
    "pool_from_settings",
    "require_operator",
    "require_team",
    "require_token",
    "stored_many",
    "tokens",
]


if not TYPE_CHECKING:
    __getattr__, __dir__ = lazy_exports(__name__, {
        "service": ("tokens",),
        "service.accounts": ("ensure_team_account",),
        "service.admin": ("add_team", "list_tokens"),
        "service.app": ("create_app", "open_storage", "pool_from_settings"),
        "service.services": ("Services",),
        "service.deps": (
            "DbSession", "OperatorPrincipal", "TeamPrincipal", "get_db", "get_services",
            "require_operator", "require_team", "require_token",
        ),
        "service.errors": ("ClientError", "InvalidInput", "NotFound", "ServiceError"),
        "service.results": ("stored_many",),
        "service.settings": ("Settings", "open_data_dir", "open_database"),
        "service.tokens": ("Principal",),
        "service.views": ("SubmissionReport",),
    })
