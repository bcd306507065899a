"""The league's submission service (``hlvs serve``): teams, tokens, team files, test matches.

Public surface: :func:`create_app` and :class:`Settings` to build the app; ``require_team`` /
``require_operator`` (FastAPI dependencies) and :class:`Principal` for routers of other
packages; :class:`MatchPool` is the port a cluster implements to play matches.
"""

from __future__ import annotations

from service.app import ROUTER_MODULES, Services, create_app
from service.deps import (
    OperatorPrincipal,
    TeamPrincipal,
    get_db,
    require_operator,
    require_team,
    require_token,
)
from service.errors import ServiceError
from service.settings import Settings
from service.tokens import Principal

__all__ = [
    "OperatorPrincipal",
    "Principal",
    "ROUTER_MODULES",
    "ServiceError",
    "Services",
    "Settings",
    "TeamPrincipal",
    "create_app",
    "get_db",
    "require_operator",
    "require_team",
    "require_token",
]
