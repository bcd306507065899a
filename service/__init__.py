"""The league's submission service (``hlvs serve``): teams, tokens, team files, test matches.

Public surface: :func:`create_app` and :class:`Settings` to build the app; ``require_team`` /
``require_operator`` (FastAPI dependencies) and :class:`Principal` for routers of other
packages; :class:`MatchPool` is the port a cluster implements to play matches.

The names are imported on first use, so that ``hlvs --help`` (which reads
``hlvs.commands.service``) does not import FastAPI and SQLAlchemy.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    from service.app import Services, create_app, pool_from_settings
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
    from service.errors import NotFound, ServiceError
    from service.settings import Settings
    from service.tokens import Principal

_WHERE = {
    "DbSession": "service.deps",
    "NotFound": "service.errors",
    "OperatorPrincipal": "service.deps",
    "Principal": "service.tokens",
    "ServiceError": "service.errors",
    "Services": "service.app",
    "Settings": "service.settings",
    "TeamPrincipal": "service.deps",
    "create_app": "service.app",
    "get_db": "service.deps",
    "get_services": "service.deps",
    "pool_from_settings": "service.app",
    "require_operator": "service.deps",
    "require_team": "service.deps",
    "require_token": "service.deps",
}


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'service' has no attribute {name!r}")
    value = getattr(importlib.import_module(_WHERE[name]), name)
    globals()[name] = value
    return value


__all__ = [
    "DbSession",
    "NotFound",
    "OperatorPrincipal",
    "Principal",
    "ServiceError",
    "Services",
    "Settings",
    "TeamPrincipal",
    "create_app",
    "get_db",
    "get_services",
    "pool_from_settings",
    "require_operator",
    "require_team",
    "require_token",
]
