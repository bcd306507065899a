"""Queueing a finished match's logs as pending sets in the local store.

Each team's folder (``teams/<color>/`` of the match output) becomes one set; the rest of the
match output (recording, referee and GameController logs, results) becomes the ``public`` set
when the operator gives a public target. Of the undelivered sets of a team only the
:data:`KEEP_UNDELIVERED` newest are kept: the oldest are deleted and logged, as the league rules
ask. Public sets are never pruned. A folder without files makes no set (it is logged), and sets
without files never count towards the limit, so that queueing a match again cannot push a real
set out.
"""

from __future__ import annotations

import logging
import shutil
from collections.abc import Mapping
from pathlib import Path

from orchestrator.delivery import store as st

__all__ = ["KEEP_UNDELIVERED", "PUBLIC_TEAM", "TEAMS_FOLDER", "enqueue_match_logs"]

log = logging.getLogger(__name__)

KEEP_UNDELIVERED = 3
PUBLIC_TEAM = "public"
TEAMS_FOLDER = "teams"


def enqueue_match_logs(
    match_dir: Path,
    *,
    match_id: str,
    teams: Mapping[str, tuple[str, Path | None]],
    public_target: Path | None,
    store: Path,
    move_team_logs: bool = True,
) -> list[st.PendingSet]:
    """Turn a finished match's logs into pending sets.

    Args:
        match_dir: the match output; ``teams/<color>/`` holds each team's logs.
        teams: color -> (team name, credentials.json of the team or None).
        public_target: the operator's credentials.json for the public logs (everything in
            ``match_dir`` outside ``teams/``), or None to keep them local only.
        move_team_logs: move team files into the store (they leave ``match_dir``) instead of
            linking them.
    """
    created = []
    with st.locked(store):
        for color, (team, credentials) in sorted(teams.items()):
            folder = match_dir / TEAMS_FOLDER / color
            if not folder.is_dir():
                log.warning(
                    "match %s: no logs of team %s (%s) in %s", match_id, team, color, folder
                )
            sources = _files_under(folder, exclude=None)
            if not sources:
                log.warning("match %s: team %s (%s) has no log files: no set made", match_id,
                            team, color)
                continue
            created.append(
                st.create_set(
                    store,
                    match_id=match_id,
                    team=team,
                    kind="team",
                    credentials=credentials,
                    sources=sources,
                    move=move_team_logs,
                )
            )
            if move_team_logs and folder.is_dir():
                shutil.rmtree(folder)  # only empty folders are left
            log.info("match %s: queued %d log files of team %s", match_id, len(sources), team)
            _prune(store, team)
        public = (_public_files(match_dir) if public_target is not None else [])
        if public_target is not None and not public:
            log.warning("match %s: no public log files: no set made", match_id)
        elif public_target is not None:
            created.append(
                st.create_set(
                    store,
                    match_id=match_id,
                    team=PUBLIC_TEAM,
                    kind="public",
                    credentials=public_target,
                    sources=public,
                    move=False,
                )
            )
            log.info("match %s: queued %d public log files", match_id, len(public))
    return created


def _public_files(match_dir: Path) -> list[tuple[Path, str]]:
    """The public set's files: the match's ``public/`` folder at the set's top (delivered to
    ``<match>/public/...``, not ``<match>/public/public/...``), the rest beside it."""
    found = [f for f in _files_under(match_dir, exclude=match_dir / TEAMS_FOLDER)
             if not _earlier_team_file(f[1])]
    names = {rel for _, rel in found}
    out = []
    for path, rel in found:
        inner = rel.removeprefix(f"{PUBLIC_TEAM}/")
        out.append((path, inner if inner != rel and inner not in names else rel))
    return out


def _earlier_team_file(rel: str) -> bool:
    """A team's file of an earlier attempt (``attempt-<n>/teams/...``): never public."""
    parts = rel.split("/")
    return len(parts) > 2 and parts[0].startswith("attempt-") and parts[1] == TEAMS_FOLDER


def _files_under(folder: Path, *, exclude: Path | None) -> list[tuple[Path, str]]:
    if not folder.is_dir():
        return []
    found = []
    for path in sorted(folder.rglob("*")):
        if exclude is not None and path.is_relative_to(exclude):
            continue
        if path.is_file() and not path.is_symlink():
            found.append((path, path.relative_to(folder).as_posix()))
    return found


def _prune(store: Path, team: str) -> None:
    sets = [s for s in st.list_sets(store) if s.team == team and s.kind == "team" and s.files]
    for old in sets[: max(0, len(sets) - KEEP_UNDELIVERED)]:
        with st.claimed(old) as mine:
            if not mine:
                continue  # being delivered right now
            st.remove_set(old)
        log.warning(
            "match %s: deleted the undelivered logs of %s (%d files, %.1f MB): more "
            "than %d sets were waiting",
            old.match_id,
            team,
            len(old.files),
            old.total_bytes / 1e6,
            KEEP_UNDELIVERED,
        )
