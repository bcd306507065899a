"""Each team's account in a cluster pool (Slurm): its test matches are charged to it.

On the Slurm pool every team gets a Slurm account of its own, made with ``sacctmgr`` when the
team is added (``hlvs admin team add`` with ``HLVS_SERVICE_POOL=slurm``) or, at the latest,
before its first test match is submitted: ``GrpJobs=1`` (one of its jobs runs at a time) and
``MaxSubmitJobs`` = ``HLVS_SERVICE_SLURM_MAX_QUEUED`` (a bounded queue). The account's name is
kept in ``teams.slurm_account``. When Slurm keeps a team's match waiting (its quota, free nodes,
priority), its reason is the submission's ``waiting_reason``. Pools without accounts (the local
engine) have no ``ensure_account`` and get no account.
"""

from __future__ import annotations

import logging
import re
from typing import Any

from sqlalchemy.orm import Session

from service.db import Team
from service.settings import Settings

log = logging.getLogger(__name__)


def account_name(team_id: int, team_name: str) -> str:
    """``hlvs_t<id>_<name>``: lower case, letters, digits and '_' (Slurm folds case)."""
    slug = re.sub(r"[^a-z0-9]+", "_", team_name.lower()).strip("_")[:24]
    return f"hlvs_t{team_id}_{slug}" if slug else f"hlvs_t{team_id}"


def supports_accounts(pool: Any) -> bool:
    return callable(getattr(pool, "ensure_account", None))


def ensure_team_account(session: Session, pool: Any, team: Team, settings: Settings) -> str:
    """The team's account, made in the pool first if this service has not made it yet
    (``PoolError`` when the cluster refuses)."""
    if team.slurm_account:
        return team.slurm_account
    name = account_name(team.id, team.name)
    pool.ensure_account(name, max_running=1, max_queued=settings.slurm_max_queued)
    team.slurm_account = name
    log.info("team %s: Slurm account %s (GrpJobs=1, MaxSubmitJobs=%d)", team.name, name,
             settings.slurm_max_queued)
    return name


__all__ = ["account_name", "ensure_team_account", "supports_accounts"]
