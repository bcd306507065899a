"""The replay writer: :class:`Recorder` writes a match as a version 3 ``.hlvsrec`` file.

The format (self-describing header with the scene, chunks of frames, an index and a trailer for
seeking) is described in :mod:`simulator.replay.format`; reading is :mod:`simulator.replay`.
"""

from __future__ import annotations

import contextlib
import logging
import zlib
from pathlib import Path
from typing import IO

import numpy as np

from contracts import EventRecord, GameStateRecord, to_data
from simulator.replay.format import (
    CHUNK,
    FORMAT_VERSION,
    INDEX,
    INDEX_MAGIC,
    MAGIC,
    RECORD_HEAD,
    TRAILER,
    U32,
    ChunkMeta,
    HeaderRecord,
    RobotEntry,
    dumps,
    encode_poses,
)
from simulator.replay.reader import load_replay
from simulator.replay.scene import scene_of
from simulator.world import World

log = logging.getLogger(__name__)

ZLIB_LEVEL = 6


def replay_header(
    world: World, *, match_id: str, rate_hz: float, chunk_frames: int
) -> HeaderRecord:
    """The header of a version 3 replay of ``world`` (also the scene sent to live viewers)."""
    return {
        "format": "hlvsrec",
        "version": FORMAT_VERSION,
        "match_id": match_id,
        "seed": world.seed,
        "field_class": world.field.field_class.value,
        "physics_dt_s": world.physics_dt_s,
        "step_ms": world.step_ms,
        "rate_hz": rate_hz,
        "chunk_frames": chunk_frames,
        "robots": [
            to_data(
                RobotEntry(
                    team=p.id.team.value,
                    number=p.id.number,
                    model=p.model,
                    x_m=p.x_m,
                    y_m=p.y_m,
                    yaw_rad=p.yaw_rad,
                )
            )
            for p in world.placements
        ],
        "body_names": [world.model.body(i).name for i in range(world.model.nbody)],
        "scene": scene_of(
            world.model, world.placements, world.field, world.look, world.camera_model
        ),
    }


class Recorder:
    """Writes a replay while a match runs: call :meth:`record` after every step (it writes a
    frame when one is due at ``rate_hz`` of simulated time), :meth:`event` for referee events
    (stored with the next frame) and :meth:`close` at the end. The first frame, written on
    creation, holds the initial state with an empty game state. Frames are written in chunks of
    ``chunk_frames`` (flushed to disk as each chunk completes).

    A write that fails (the disk full, the folder gone) cuts the replay, never the match: the
    file keeps its whole chunks (a reader scans a file without an index, see
    :mod:`simulator.replay.reader`), :attr:`cut` says where and why, and the recorder writes
    nothing more."""

    def __init__(
        self,
        path: str | Path,
        world: World,
        *,
        match_id: str,
        rate_hz: float = 25.0,
        chunk_frames: int = 25,
    ) -> None:
        if rate_hz <= 0:
            raise ValueError(f"rate_hz must be positive, not {rate_hz}")
        if chunk_frames <= 0:
            raise ValueError(f"chunk_frames must be positive, not {chunk_frames}")
        self.path = Path(path)
        self.rate_hz = rate_hz
        self.chunk_frames = chunk_frames
        self._period_ms = 1000.0 / rate_hz
        self._frames = 0
        self._events: list[EventRecord] = []
        self._game: GameStateRecord = {}
        self._last_time_ms = -1
        self._pending: ChunkMeta = self._empty_chunk()
        self._poses: list[np.ndarray] = []
        self._index_chunks: list[list[int]] = []
        self._index_events: list[EventRecord] = []
        self._offset = 0
        self.cut = ""
        """Empty, or why and at which simulated time the replay was cut short."""
        self._out: IO[bytes] | None = self.path.open("wb")
        header = replay_header(world, match_id=match_id, rate_hz=rate_hz, chunk_frames=chunk_frames)
        blob = dumps(header)
        self._emit(MAGIC + U32.pack(len(blob)) + blob)
        self.record(world, {})  # the initial state

    @staticmethod
    def _empty_chunk() -> ChunkMeta:
        return {"times": [], "games": [], "events": []}

    @property
    def frames_written(self) -> int:
        return self._frames

    def record(self, world: World, game_state: GameStateRecord) -> None:
        if self.cut:
            return
        self._game = game_state
        if world.sim_time_ms >= self._frames * self._period_ms:
            self._add(world.sim_time_ms, world.data.xpos, world.data.xquat)
            while self._frames * self._period_ms <= world.sim_time_ms:
                self._frames += 1

    def event(self, event: EventRecord) -> None:
        if not self.cut:
            self._events.append(event)

    def _emit(self, blob: bytes, *, flush: bool = False) -> None:
        if self._out is None:
            raise ValueError(f"{self.path}: recorder is closed")
        try:
            self._out.write(blob)
            if flush:
                self._out.flush()
        except OSError as exc:
            self._cut_short(exc)
            return
        self._offset += len(blob)

    def _cut_short(self, exc: OSError) -> None:
        at = max(self._last_time_ms, 0)
        self.cut = (f"{self.path}: {exc.strerror or exc}: the replay ends before {at} ms of "
                    "simulated time (the match went on)")
        log.error("replay cut short: %s", self.cut)
        out, self._out = self._out, None
        if out is not None:
            with contextlib.suppress(OSError):  # what is buffered cannot be written either
                out.close()

    def _add(self, sim_time_ms: int, xpos: np.ndarray, xquat: np.ndarray) -> None:
        if self._out is None:
            if self.cut:
                return
            raise ValueError(f"{self.path}: recorder is closed")
        chunk = self._pending
        chunk["times"].append(sim_time_ms)
        chunk["games"].append(self._game)
        chunk["events"].append(self._events)
        self._index_events.extend({**e, "frame_ms": sim_time_ms} for e in self._events)
        self._events = []
        self._poses.append(np.concatenate([xpos, xquat], axis=1))
        self._last_time_ms = sim_time_ms
        if len(chunk["times"]) >= self.chunk_frames:
            self._flush_chunk()

    def _flush_chunk(self) -> None:
        chunk = self._pending
        if not chunk["times"]:
            return
        meta = dumps(chunk)
        poses = zlib.compress(encode_poses(np.stack(self._poses)), ZLIB_LEVEL)
        payload = U32.pack(len(meta)) + meta + poses
        times = chunk["times"]
        self._index_chunks.append([self._offset, times[0], times[-1], len(times)])
        self._emit(RECORD_HEAD.pack(CHUNK, len(payload)) + payload, flush=True)
        self._pending = self._empty_chunk()
        self._poses = []

    def close(self, world: World | None = None) -> None:
        """Write the frame of events not yet written (when ``world`` is given), the last chunk,
        the index and the trailer, and close."""
        if self._out is None:
            return
        if self._events and world is not None and world.sim_time_ms != self._last_time_ms:
            self._add(world.sim_time_ms, world.data.xpos, world.data.xquat)
        self._flush_chunk()
        if self._out is None:  # cut short by the last chunk
            return
        index = dumps(
            {
                "chunks": self._index_chunks,
                "events": self._index_events,
                "frames": sum(c[3] for c in self._index_chunks),
                "duration_ms": self._last_time_ms,
            }
        )
        at = self._offset
        self._emit(RECORD_HEAD.pack(INDEX, len(index)) + index + TRAILER.pack(at, INDEX_MAGIC),
                   flush=True)
        if self._out is None:  # cut short by the last writes
            return
        try:
            self._out.close()
        except OSError as exc:
            self._cut_short(exc)
        self._out = None

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


__all__ = ["Recorder", "load_replay", "replay_header"]
