"""Reading replays of every version, with seeking: :class:`ReplayFile` and :func:`load_replay`.

Versions 2 and 3 are described in :mod:`simulator.replay.format`.

Version 1 (the first format, still read)::

    b"HLVSREC\\0", u32 header length, header JSON (version 1, no scene, no chunk_frames)
    frames, each: u32 payload length, then u32 sim_time_ms, u32 meta length,
        meta JSON {"game": {...}, "events": [...]}, zlib(float32[bodies * 7])

It has no index: opening one scans the frame heads once and groups the frames into chunks of
``V1_CHUNK_FRAMES`` so that both versions are read the same way afterwards.
"""

from __future__ import annotations

import json
import os
import struct
import zlib
from collections.abc import Iterator
from pathlib import Path
from typing import IO, cast

import numpy as np

from contracts import ContractError, EventRecord, GameStateRecord, from_data
from simulator.errors import ReplayError
from simulator.replay.format import (
    CHUNK,
    INDEX,
    INDEX_MAGIC,
    MAGIC,
    POSE_WIDTH,
    RECORD_HEAD,
    SUPPORTED_VERSIONS,
    TRAILER,
    U32,
    ChunkMeta,
    ChunkRef,
    FrameBlock,
    HeaderRecord,
    Replay,
    ReplayFrame,
    ReplayHeader,
    RobotEntry,
    decode_poses,
    unshuffle,
)

V1_CHUNK_FRAMES = 25
_V1_FRAME_HEAD = struct.Struct("<II")
_CORRUPT = (struct.error, zlib.error, ValueError, KeyError, TypeError, IndexError)


def _header(data: HeaderRecord, *, source: str) -> ReplayHeader:
    return ReplayHeader(
        version=int(data["version"]),
        match_id=str(data["match_id"]),
        seed=int(data["seed"]),
        field_class=str(data["field_class"]),
        physics_dt_s=float(data["physics_dt_s"]),
        step_ms=int(data["step_ms"]),
        rate_hz=float(data["rate_hz"]),
        robots=tuple(
            from_data(RobotEntry, r, source=source, pointer=f"/robots/{i}")
            for i, r in enumerate(data["robots"])
        ),
        body_names=tuple(str(n) for n in data["body_names"]),
        scene=data.get("scene"),
        raw=data,
    )


class ReplayFile:
    """An open replay: header, chunk index and referee events; chunks read on demand.

    Use as a context manager or call :meth:`close`. Every problem raises ReplayError naming
    the file. ``indexed`` is False for version 1 files and for files whose writer died (no
    trailer), which were scanned instead.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        try:
            self._file: IO[bytes] = self.path.open("rb")
        except OSError as exc:
            raise ReplayError(path=str(self.path), reason=f"cannot read: {exc}") from exc
        try:
            self._open()
        except ReplayError:
            self._file.close()
            raise
        except _CORRUPT as exc:
            self._file.close()
            raise self._error(f"truncated or corrupt: {exc}") from exc

    def _error(self, reason: str) -> ReplayError:
        return ReplayError(path=str(self.path), reason=reason)

    def _read_at(self, offset: int, size: int) -> bytes:
        self._file.seek(offset)
        blob = self._file.read(size)
        if len(blob) != size:
            raise struct.error(f"{size} bytes wanted at offset {offset}, {len(blob)} there")
        return blob

    def _open(self) -> None:
        self.size = os.fstat(self._file.fileno()).st_size
        if self._file.read(len(MAGIC)) != MAGIC:
            raise self._error("not an hlvsrec file (bad magic)")
        (length,) = U32.unpack(self._read_at(len(MAGIC), 4))
        raw = json.loads(self._read_at(len(MAGIC) + 4, length))
        if not isinstance(raw, dict):
            raise self._error("the header is not a JSON object")
        version = raw.get("version")
        if version not in SUPPORTED_VERSIONS:
            raise self._error(
                f"format version {version!r}; this reader knows versions "
                f"{', '.join(str(v) for v in SUPPORTED_VERSIONS)} (a newer hlvs-runner wrote it?)"
            )
        try:  # each field converted and checked
            self.header = _header(cast("HeaderRecord", raw), source=str(self.path))
        except ContractError as exc:
            raise self._error(f"header: {exc.pointer}: {exc.reason}") from exc
        self.nbody = len(self.header.body_names)
        self._data_start = len(MAGIC) + 4 + length
        self.events: tuple[EventRecord, ...] = ()
        self._v1_frames: list[list[int]] = []
        if version == 1:
            self.indexed = False
            self.chunks = self._scan_v1()
        elif not self._read_index():
            self.indexed = False
            self.chunks = self._scan_v2()
        else:
            self.indexed = True

    # -- version 2 -------------------------------------------------------------------------

    def _read_index(self) -> bool:
        if self.size < self._data_start + TRAILER.size:
            return False
        offset, magic = TRAILER.unpack(self._read_at(self.size - TRAILER.size, TRAILER.size))
        if magic != INDEX_MAGIC:
            return False
        kind, length = RECORD_HEAD.unpack(self._read_at(offset, RECORD_HEAD.size))
        if kind != INDEX:
            raise self._error(f"the trailer points at a record of kind {kind}, not the index")
        index = json.loads(self._read_at(offset + RECORD_HEAD.size, length))
        self.chunks = tuple(
            ChunkRef(offset=int(o), first_ms=int(a), last_ms=int(b), frames=int(n))
            for o, a, b, n in index["chunks"]
        )
        self.events = tuple(index["events"])
        return True

    def _scan_v2(self) -> tuple[ChunkRef, ...]:
        chunks: list[ChunkRef] = []
        events: list[EventRecord] = []
        offset = self._data_start
        while offset + RECORD_HEAD.size <= self.size:
            kind, length = RECORD_HEAD.unpack(self._read_at(offset, RECORD_HEAD.size))
            if offset + RECORD_HEAD.size + length > self.size:
                break  # the writer died inside this record
            if kind == CHUNK:
                meta = self._chunk_meta(offset)[0]
                times = meta["times"]
                chunks.append(
                    ChunkRef(offset=offset, first_ms=times[0], last_ms=times[-1], frames=len(times))
                )
                for time_ms, frame_events in zip(times, meta["events"], strict=True):
                    events.extend({**e, "frame_ms": time_ms} for e in frame_events)
            elif kind != INDEX:
                raise self._error(f"record of unknown kind {kind} at offset {offset}")
            offset += RECORD_HEAD.size + length
        self.events = tuple(events)
        return tuple(chunks)

    def _chunk_meta(self, offset: int) -> tuple[ChunkMeta, int, int]:
        kind, length = RECORD_HEAD.unpack(self._read_at(offset, RECORD_HEAD.size))
        if kind != CHUNK:
            raise self._error(f"no chunk record at offset {offset} (kind {kind})")
        start = offset + RECORD_HEAD.size
        (meta_len,) = U32.unpack(self._read_at(start, 4))
        meta = json.loads(self._read_at(start + 4, meta_len))
        return meta, start + 4 + meta_len, start + length

    def _read_chunk_v2(self, ref: ChunkRef) -> FrameBlock:
        meta, poses_at, end = self._chunk_meta(ref.offset)
        frames = len(meta["times"])
        blob = zlib.decompress(self._read_at(poses_at, end - poses_at))
        if self.header.version == 2:
            poses = unshuffle(blob, frames * self.nbody * POSE_WIDTH).reshape(
                frames, self.nbody, POSE_WIDTH
            )
        else:
            poses = decode_poses(blob, frames, self.nbody)
        return FrameBlock(
            times_ms=np.asarray(meta["times"], dtype=np.int64),
            games=list(meta["games"]),
            events=list(meta["events"]),
            poses=poses,
        )

    # -- version 1 -------------------------------------------------------------------------

    def _scan_v1(self) -> tuple[ChunkRef, ...]:
        frames: list[tuple[int, int]] = []  # (offset, sim_time_ms)
        events: list[EventRecord] = []
        offset = self._data_start
        while offset < self.size:
            (length,) = U32.unpack(self._read_at(offset, 4))
            time_ms, meta_len = _V1_FRAME_HEAD.unpack(self._read_at(offset + 4, 8))
            if offset + 4 + length > self.size:
                raise struct.error(f"frame at offset {offset} ends past the end of the file")
            meta = json.loads(self._read_at(offset + 12, meta_len))
            frame_events: list[EventRecord] = meta["events"]
            events.extend({**e, "frame_ms": time_ms} for e in frame_events)
            frames.append((offset, time_ms))
            offset += 4 + length
        self.events = tuple(events)
        chunks = []
        for k in range(0, len(frames), V1_CHUNK_FRAMES):
            run = frames[k : k + V1_CHUNK_FRAMES]
            self._v1_frames.append([o for o, _ in run])
            chunks.append(
                ChunkRef(offset=run[0][0], first_ms=run[0][1], last_ms=run[-1][1], frames=len(run))
            )
        return tuple(chunks)

    def _read_chunk_v1(self, index: int) -> FrameBlock:
        times: list[int] = []
        games: list[GameStateRecord] = []
        events: list[list[EventRecord]] = []
        poses = []
        for offset in self._v1_frames[index]:
            (length,) = U32.unpack(self._read_at(offset, 4))
            payload = self._read_at(offset + 4, length)
            time_ms, meta_len = _V1_FRAME_HEAD.unpack_from(payload, 0)
            meta = json.loads(payload[8 : 8 + meta_len])
            values = np.frombuffer(
                zlib.decompress(payload[8 + meta_len :]), dtype="<f4", count=self.nbody * 7
            )
            times.append(time_ms)
            games.append(meta["game"])
            events.append(meta["events"])
            poses.append(values.reshape(self.nbody, POSE_WIDTH))
        return FrameBlock(
            times_ms=np.asarray(times, dtype=np.int64),
            games=games,
            events=events,
            poses=np.stack(poses) if poses else np.zeros((0, self.nbody, 7), np.float32),
        )

    # -- public ----------------------------------------------------------------------------

    @property
    def duration_ms(self) -> int:
        return self.chunks[-1].last_ms if self.chunks else 0

    @property
    def frame_count(self) -> int:
        return sum(c.frames for c in self.chunks)

    def chunk_at(self, time_ms: float) -> int:
        """Index of the chunk holding the last frame at or before ``time_ms`` (0 if earlier)."""
        starts = [c.first_ms for c in self.chunks]
        return max(0, int(np.searchsorted(starts, time_ms, side="right")) - 1)

    def read_chunk(self, index: int) -> FrameBlock:
        if not 0 <= index < len(self.chunks):
            raise self._error(f"chunk {index} out of range (0..{len(self.chunks) - 1})")
        try:
            if self.header.version == 1:
                return self._read_chunk_v1(index)
            return self._read_chunk_v2(self.chunks[index])
        except _CORRUPT as exc:
            raise self._error(f"truncated or corrupt chunk {index}: {exc}") from exc

    def frames(self) -> Iterator[ReplayFrame]:
        for index in range(len(self.chunks)):
            block = self.read_chunk(index)
            for k in range(len(block.times_ms)):
                yield ReplayFrame(
                    sim_time_ms=int(block.times_ms[k]),
                    game=block.games[k],
                    events=block.events[k],
                    poses=block.poses[k],
                )

    def close(self) -> None:
        self._file.close()

    def __enter__(self) -> ReplayFile:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def load_replay(path: str | Path) -> Replay:
    """Read a whole replay of any version; ReplayError names the file and the problem."""
    with ReplayFile(path) as replay:
        return Replay(header=replay.header, frames=tuple(replay.frames()))
