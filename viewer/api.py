"""The viewer's HTTP API and pages (FastAPI router), shared by ``hlvs view`` and ``hlvs serve``.

Pages: ``/watch/`` (index), ``/watch/replay/<id>``, ``/watch/live/<id>`` and the service pages;
every one is ``static/index.html`` with the bundled front end (``static/app.js``), which picks
the page from the path. API under ``/api/viewer``:

- ``GET index``: the replays and live matches known;
- ``GET replays/<id>/meta``: match id, format version, frame rate, duration, body count, the
  scene (``simulator.replay.scene``), the chunk index ``[[first_ms, last_ms, frames]...]``, the
  referee events (each with the ``frame_ms`` it was recorded with), whether statistics exist,
  the teams' names (``{"red": ..., "blue": ...}``, null when not known) and whether the replay
  is complete (its recorder closed it: the match is over);
- ``GET replays/<id>/chunks/<k>``: one chunk of frames, binary: u32 JSON length, JSON
  ``{"times": [...], "games": [...]}``, zero padding to 4 bytes, then float32 poses
  (frames x bodies x 7, little-endian);
- ``GET replays/<id>/stats``: the ``api_stats.jsonl`` samples as a JSON list;
- ``GET live/<id>/stream``: server-sent events ``teams`` (first, when the names are known),
  ``scene``, ``state``, ``event``, ``poses`` (base64 of the telemetry's binary poses) from the
  match's telemetry.
"""

from __future__ import annotations

import asyncio
import base64
import json
import struct
from collections.abc import AsyncIterator
from functools import lru_cache
from pathlib import Path
from typing import Any, Protocol

from fastapi import APIRouter, Depends, FastAPI, HTTPException
from fastapi.responses import FileResponse, Response, StreamingResponse
from fastapi.staticfiles import StaticFiles

from contracts import files
from simulator import ReplayError, read_stats
from simulator.replay import ReplayFile, SceneRecord, scene_for
from viewer.live import FeedFactory, LiveUnavailable, ZenohFeed
from viewer.sources import Catalog, LiveSource, ReplaySource, Teams

STATIC = Path(__file__).parent / "static"
API_PREFIX = "/api/viewer"
KEEPALIVE_S = 10.0


def _missing(what: str, key: str, known: list[str]) -> HTTPException:
    hint = f"; known: {', '.join(sorted(known)[:20])}" if known else ""
    return HTTPException(status_code=404, detail=f"no {what} {key!r}{hint}")


class _OpenReplays:
    """Keeps replay files open (header and index read once) per source path and mtime."""

    def __init__(self) -> None:
        self._open = lru_cache(maxsize=16)(self._load)

    @staticmethod
    def _load(path: Path, mtime_ns: int) -> tuple[ReplayFile, SceneRecord]:
        del mtime_ns  # part of the cache key: a replay still being written is reopened
        replay = ReplayFile(path)
        return replay, scene_for(replay.header, str(path))

    def get(self, source: ReplaySource) -> tuple[ReplayFile, SceneRecord]:
        try:
            return self._open(source.path, source.path.stat().st_mtime_ns)
        except OSError as exc:
            raise HTTPException(status_code=404, detail=f"{source.path}: {exc}") from exc
        except ReplayError as exc:
            raise HTTPException(status_code=422, detail=str(exc)) from exc


class Resolver(Protocol):
    """Finds replays and live matches; each method is used as a FastAPI dependency, so an
    implementation may ask for more (a token, a database session) in its own signature."""

    def replay(self, replay_id: str) -> ReplaySource: ...

    def live(self, match_id: str) -> LiveSource: ...

    def listing(self) -> tuple[list[ReplaySource], list[LiveSource]]: ...


class CatalogResolver:
    """Replays and live matches of a fixed :class:`Catalog` (``hlvs view``: no accounts)."""

    def __init__(self, catalog: Catalog) -> None:
        self.catalog = catalog

    def replay(self, replay_id: str) -> ReplaySource:
        source = self.catalog.replays.get(replay_id)
        live = self.catalog.live.get(replay_id)
        if live is not None and live.replay_path is not None:
            # a match watched live: its replay as written so far, the public copy once
            # collected (asked again each time: the copy being written goes away then)
            folder = live.replay_path.parents[2]
            for path in (folder / "public" / files.REPLAY, live.replay_path):
                if source is not None and source.path == path:
                    break
                if path.is_file():
                    self.catalog.replays.pop(replay_id, None)
                    source = self.catalog.add_replay(path, id=replay_id, teams=live.teams)
                    break
        if source is None:
            raise _missing("replay", replay_id, list(self.catalog.replays))
        return source

    def live(self, match_id: str) -> LiveSource:
        live = self.catalog.live.get(match_id)
        if live is None:
            raise _missing("live match", match_id, list(self.catalog.live))
        if _over(live):
            raise HTTPException(status_code=404, detail=f"the match {match_id!r} is over: its "
                                "replay is complete")
        return live

    def listing(self) -> tuple[list[ReplaySource], list[LiveSource]]:
        return list(self.catalog.replays.values()), list(self.catalog.live.values())


def _over(live: LiveSource) -> bool:
    """Whether a match known by its folder has ended: its output collected (the public
    replay), or its replay closed by the recorder (a match whose output was not collected)."""
    if live.replay_path is None:
        return False
    if (live.replay_path.parents[2] / "public" / files.REPLAY).is_file():
        return True
    try:
        with ReplayFile(live.replay_path) as replay:
            return replay.indexed
    except (OSError, ReplayError):
        return False


def build_router(resolver: Any, *, feed_factory: FeedFactory = ZenohFeed,
                 prefix: str = API_PREFIX, pages: bool = True) -> APIRouter:
    """The API (under ``prefix``) and, with ``pages``, the page routes; ``resolver`` is a
    :class:`Resolver`."""
    API_PREFIX = prefix  # noqa: N806 - the routes below read the prefix under this name
    router = APIRouter()
    replays = _OpenReplays()
    # dependencies as defaults: annotations are strings here and cannot name local aliases
    by_id = Depends(resolver.replay)
    live_by_id = Depends(resolver.live)
    found_all = Depends(resolver.listing)

    @router.get(f"{API_PREFIX}/index")
    def index(found: tuple[list[ReplaySource], list[LiveSource]] = found_all) -> dict[str, Any]:
        return _index(replays, *found)

    @router.get(f"{API_PREFIX}/replays/{{replay_id}}/meta")
    def meta(source: ReplaySource = by_id) -> dict[str, Any]:
        replay, scene = replays.get(source)
        return _meta(source, replay, scene)

    @router.get(f"{API_PREFIX}/replays/{{replay_id}}/chunks/{{index}}")
    def chunk(index: int, source: ReplaySource = by_id) -> Response:
        replay, _ = replays.get(source)
        return Response(_chunk_bytes(replay, index), media_type="application/octet-stream",
                        headers={"Cache-Control": "max-age=60"})

    @router.get(f"{API_PREFIX}/replays/{{replay_id}}/stats")
    def stats(source: ReplaySource = by_id) -> list[dict[str, Any]]:
        # plain dicts for the response (its model is free JSON, as the samples were written)
        samples = read_stats(source.stats_path) if source.stats_path is not None else []
        return [dict(sample) for sample in samples]

    @router.get(f"{API_PREFIX}/live/{{match_id}}/stream")
    async def stream(live: LiveSource = live_by_id) -> StreamingResponse:
        return StreamingResponse(
            _sse(live.endpoint, live.match_id, feed_factory, teams=live.teams),
            media_type="text/event-stream",
            headers={"Cache-Control": "no-cache"},
        )

    if pages:
        @router.get("/watch", include_in_schema=False)
        @router.get("/watch/{page:path}", include_in_schema=False)
        def page(page: str = "") -> FileResponse:
            del page
            return FileResponse(STATIC / "index.html")

    return router


def _index(
    replays: _OpenReplays, sources: list[ReplaySource], live: list[LiveSource]
) -> dict[str, Any]:
    """The replays that open (one that does not is left out) and the live matches."""
    listing = []
    for source in sources:
        try:
            replay, _ = replays.get(source)
        except HTTPException:
            continue
        listing.append({"id": source.id, "match_id": replay.header.match_id,
                        "duration_ms": replay.duration_ms, "version": replay.header.version,
                        "teams": _teams(source.teams)})
    return {"replays": listing,
            "live": [{"id": source.id, "teams": _teams(source.teams)} for source in live]}


def _meta(source: ReplaySource, replay: ReplayFile, scene: SceneRecord) -> dict[str, Any]:
    """A replay's description for the player: its match, timing, chunks, events and scene."""
    return {
        "id": source.id,
        "match_id": replay.header.match_id,
        "version": replay.header.version,
        "rate_hz": replay.header.rate_hz,
        "duration_ms": replay.duration_ms,
        "body_count": replay.nbody,
        "robots": [r.key for r in replay.header.robots],
        "chunks": [[c.first_ms, c.last_ms, c.frames] for c in replay.chunks],
        "events": list(replay.events),
        "scene": scene,
        "has_stats": source.stats_path is not None,
        "teams": _teams(source.teams),
        "complete": replay.indexed,  # closed by its recorder: the match is over
    }


def _chunk_bytes(replay: ReplayFile, index: int) -> bytes:
    """Chunk ``index`` of ``replay`` on the wire: the JSON head's length (4 bytes, little
    endian), the head (frame times and game states) padded to 4 bytes, then the poses as
    little-endian float32. 404 for a chunk out of range, 422 for one that cannot be read."""
    if not 0 <= index < len(replay.chunks):
        raise HTTPException(
            status_code=404, detail=f"chunk {index} out of range 0..{len(replay.chunks) - 1}"
        )
    try:
        block = replay.read_chunk(index)
    except ReplayError as exc:
        raise HTTPException(status_code=422, detail=str(exc)) from exc
    head = json.dumps(
        {"times": block.times_ms.tolist(), "games": block.games}, separators=(",", ":")
    ).encode()
    pad = b"\0" * ((4 - len(head) % 4) % 4)
    return struct.pack("<I", len(head)) + head + pad + block.poses.astype("<f4").tobytes()


_SSE_NAMES = {"state": "state", "events": "event", "poses": "poses", "scene": "scene"}


def _teams(teams: Teams | None) -> dict[str, str] | None:
    return teams.as_json() if teams is not None else None


async def _sse(endpoint: str, match_id: str, factory: FeedFactory, *,
               teams: Teams | None = None) -> AsyncIterator[bytes]:
    loop = asyncio.get_running_loop()
    queue: asyncio.Queue[tuple[str, bytes]] = asyncio.Queue(maxsize=256)

    def on_message(kind: str, payload: bytes) -> None:
        def put() -> None:
            if kind == "poses" and queue.qsize() > 128:
                return  # a slow browser skips pose updates, never state or events
            if not queue.full():
                queue.put_nowait((kind, payload))

        loop.call_soon_threadsafe(put)

    try:
        feed = await asyncio.to_thread(factory, endpoint, match_id, on_message)
    except LiveUnavailable as exc:
        yield f"event: failure\ndata: {json.dumps(str(exc))}\n\n".encode()
        return
    try:
        yield b": connected\n\n"
        if teams is not None:
            yield f"event: teams\ndata: {json.dumps(teams.as_json())}\n\n".encode()
        while True:
            try:
                kind, payload = await asyncio.wait_for(queue.get(), KEEPALIVE_S)
            except TimeoutError:
                yield b": keep-alive\n\n"
                continue
            data = base64.b64encode(payload).decode() if kind == "poses" else payload.decode()
            yield f"event: {_SSE_NAMES[kind]}\ndata: {data}\n\n".encode()
    finally:
        await asyncio.to_thread(feed.close)


def mount_viewer(app: FastAPI, resolver: Any, *, feed_factory: FeedFactory = ZenohFeed) -> None:
    """Add the viewer's pages, API and static files to ``app`` (``resolver``: a Resolver)."""
    app.mount("/watch/static", StaticFiles(directory=STATIC), name="viewer-static")
    app.include_router(build_router(resolver, feed_factory=feed_factory))


def create_app(catalog: Catalog, *, feed_factory: FeedFactory = ZenohFeed) -> FastAPI:
    """The app of ``hlvs view``: the viewer alone, no account, no database."""
    app = FastAPI(title="hlvs view", docs_url=None, redoc_url=None)
    mount_viewer(app, CatalogResolver(catalog), feed_factory=feed_factory)
    return app
