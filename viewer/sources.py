"""What a viewer shows: replays (with their API statistics) and live matches, found from paths.

A path is a replay file, or a match folder as ``hlvs match`` / ``hlvs scrimmage`` write it:
``public/replay.hlvsrec`` once the match is over, ``simulator/out/replay.hlvsrec`` while it
runs, ``api_stats.jsonl`` beside the replay, and ``simulator/match_spec.json`` whose
``network.telemetry_listen`` is where a running match's telemetry is (the live view).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from pathlib import Path

from contracts import ContractError, MatchSpec, files
from viewer.errors import SourceError

STATS_FILE = files.API_STATS
REPLAY_SUFFIX = ".hlvsrec"
_REPLAY_PLACES = (f"public/{files.REPLAY}", f"simulator/{files.OUT_DIR}/{files.REPLAY}",
                  files.REPLAY)


@dataclass(frozen=True, slots=True)
class Teams:
    """The teams' names, as the pages' scoreboard shows them."""

    red: str
    blue: str

    def as_json(self) -> dict[str, str]:
        return {"red": self.red, "blue": self.blue}


@dataclass(frozen=True, slots=True)
class ReplaySource:
    id: str
    path: Path
    stats_path: Path | None
    teams: Teams | None = None  # None: not known (a replay file alone)


@dataclass(frozen=True, slots=True)
class LiveSource:
    id: str  # what the page's URL names it by
    match_id: str  # telemetry keys hlvs/<match_id>/...
    endpoint: str  # zenoh endpoint, e.g. tcp/10.213.4.2:7447
    replay_path: Path | None  # where the replay is being written (shown once the match is over)
    teams: Teams | None = None


@dataclass(slots=True)
class Catalog:
    """Replays and live matches by id; ids are safe in a URL path segment."""

    replays: dict[str, ReplaySource] = field(default_factory=dict)
    live: dict[str, LiveSource] = field(default_factory=dict)

    def add_replay(self, path: Path, *, id: str | None = None,
                   teams: Teams | None = None) -> ReplaySource:
        stats = path.with_name(STATS_FILE)
        source = ReplaySource(
            id=self._unique(id or _slug(path)),
            path=path,
            stats_path=stats if stats.is_file() else None,
            teams=teams or teams_of(_match_folder_of(path)),
        )
        self.replays[source.id] = source
        return source

    def _unique(self, base: str) -> str:
        name, n = base, 2
        while name in self.replays:
            name, n = f"{base}-{n}", n + 1
        return name

    def add_path(self, path: Path) -> list[str]:
        """Add a replay file or a match folder; returns the viewer paths to open (/watch/...)."""
        path = path.resolve()
        if path.is_file():
            if path.suffix != REPLAY_SUFFIX:
                raise SourceError(
                    path=str(path),
                    reason=f"not a replay (expected a *{REPLAY_SUFFIX} file or a match folder)",
                )
            return [f"/watch/replay/{self.add_replay(path).id}"]
        if not path.is_dir():
            raise SourceError(path=str(path), reason="no such file or folder")
        opened: list[str] = []
        live = _live_of(path)
        if live is not None and not (path / "public" / files.REPLAY).is_file():
            self.live[live.id] = live
            opened.append(f"/watch/live/{live.id}")
        for place in _REPLAY_PLACES:
            replay = path / place
            if replay.is_file():
                source = self.add_replay(replay, id=_slug_text(live.id if live else path.name))
                opened.append(f"/watch/replay/{source.id}")
                break
        if not opened:
            raise SourceError(
                path=str(path),
                reason="no replay in this folder (looked for "
                + ", ".join(_REPLAY_PLACES) + ") and no running match (simulator/match_spec.json)",
            )
        return opened


def _match_folder_of(replay: Path) -> Path:
    """The match folder of a replay at ``public/`` or ``simulator/out/`` of it (else its own
    folder)."""
    if replay.parent.name == "public":
        return replay.parent.parent
    if replay.parent.name == files.OUT_DIR and replay.parent.parent.name == "simulator":
        return replay.parent.parent.parent
    return replay.parent


def teams_of(folder: Path) -> Teams | None:
    """The teams' names of a match folder, from ``simulator/match_spec.json`` (None when it has
    none or it cannot be read: the pages then say RED and BLUE)."""
    spec_path = folder / "simulator" / files.MATCH_SPEC
    if not spec_path.is_file():
        return None
    try:
        spec = MatchSpec.load(spec_path)
    except ContractError:
        return None
    return _teams(spec)


def _teams(spec: MatchSpec) -> Teams | None:
    red, blue = spec.red.name, spec.blue.name
    return Teams(red=red, blue=blue) if red and blue else None


def _slug_text(text: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]+", "-", text).strip("-") or "replay"


def _slug(path: Path) -> str:
    if path.stem == "replay":  # public/replay.hlvsrec -> the match folder's name
        parent = path.parent.parent if path.parent.name in ("public", "out") else path.parent
        if path.parent.name == "out":
            parent = parent.parent
        return _slug_text(parent.name)
    return _slug_text(path.stem)


def live_of(folder: Path, *, id: str | None = None) -> LiveSource | None:
    """The live source of a running match's folder (None when it has no telemetry)."""
    live = _live_of(folder)
    if live is not None and id is not None:
        return LiveSource(id=id, match_id=live.match_id, endpoint=live.endpoint,
                          replay_path=live.replay_path, teams=live.teams)
    return live


def _live_of(folder: Path) -> LiveSource | None:
    spec_path = folder / "simulator" / files.MATCH_SPEC
    if not spec_path.is_file():
        return None
    try:
        spec = MatchSpec.load(spec_path)
    except ContractError as exc:
        raise SourceError(path=str(spec_path), reason=f"unreadable match spec: {exc}") from exc
    endpoint, match_id = spec.network.telemetry_listen, spec.match_id
    if not endpoint:
        return None
    replay = folder / "simulator" / files.OUT_DIR / files.REPLAY
    return LiveSource(
        id=_slug_text(match_id), match_id=match_id, endpoint=str(endpoint), replay_path=replay,
        teams=_teams(spec),
    )
