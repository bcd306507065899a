"""Replay files (``.hlvsrec``): a versioned header, then frames at a fixed rate.

Layout (little-endian)::

    b"HLVSREC\\0"
    u32 header length, header JSON (format, version, match_id, seed, field_class,
        physics_dt_s, step_ms, rate_hz, robots [{team, number, model, x_m, y_m, yaw_rad}],
        body_names)
    frames, each: u32 payload length, then
        u32 sim_time_ms, u32 meta length, meta JSON {"game": {...}, "events": [...]},
        zlib(float32[len(body_names) * 7]): x y z qw qx qy qz of every body (world frame)

JSON is written with sorted keys and fixed separators and zlib at a fixed level, so a match
replayed from the same seed and inputs gives a byte-identical file. Frames are independent (each
pose block compressed on its own: about 3x smaller than raw float32).
"""

from __future__ import annotations

import json
import struct
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import IO, Any

import numpy as np
import numpy.typing as npt

from referee.snapshot import RobotId, TeamColor
from simulator.errors import ReplayError
from simulator.world import RobotPlacement, World

MAGIC = b"HLVSREC\0"
FORMAT_VERSION = 1
_U32 = struct.Struct("<I")
_FRAME_HEAD = struct.Struct("<II")


def _dumps(value: object) -> bytes:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str).encode()


@dataclass(frozen=True, slots=True, kw_only=True)
class ReplayHeader:
    version: int
    match_id: str
    seed: int
    field_class: str
    physics_dt_s: float
    step_ms: int
    rate_hz: float
    robots: tuple[RobotPlacement, ...]
    body_names: tuple[str, ...]


@dataclass(frozen=True, slots=True, kw_only=True)
class ReplayFrame:
    sim_time_ms: int
    game: dict[str, Any]
    events: list[dict[str, Any]]
    poses: npt.NDArray[np.float32]  # (nbody, 7): x y z qw qx qy qz


@dataclass(frozen=True, slots=True, kw_only=True)
class Replay:
    header: ReplayHeader
    frames: tuple[ReplayFrame, ...]


class Recorder:
    """Writes a replay while a match runs: call :meth:`record` after every step (it writes a
    frame when one is due at ``rate_hz`` of simulated time), :meth:`event` for referee events
    (stored with the next frame) and :meth:`close` at the end. The first frame, written on
    creation, holds the initial state with an empty game state."""

    def __init__(
        self, path: str | Path, world: World, *, match_id: str, rate_hz: float = 25.0
    ) -> None:
        if rate_hz <= 0:
            raise ValueError(f"rate_hz must be positive, not {rate_hz}")
        self.path = Path(path)
        self.rate_hz = rate_hz
        self._period_ms = 1000.0 / rate_hz
        self._frames = 0
        self._events: list[dict[str, Any]] = []
        self._game: dict[str, Any] = {}
        self._last_time_ms = -1
        self._out: IO[bytes] | None = self.path.open("wb")
        header = {
            "format": "hlvsrec",
            "version": FORMAT_VERSION,
            "match_id": match_id,
            "seed": world.seed,
            "field_class": world.field.field_class.value,
            "physics_dt_s": world.physics_dt_s,
            "step_ms": world.step_ms,
            "rate_hz": rate_hz,
            "robots": [
                {
                    "team": p.id.team.value,
                    "number": p.id.number,
                    "model": p.model,
                    "x_m": p.x_m,
                    "y_m": p.y_m,
                    "yaw_rad": p.yaw_rad,
                }
                for p in world.placements
            ],
            "body_names": [world.model.body(i).name for i in range(world.model.nbody)],
        }
        blob = _dumps(header)
        self._out.write(MAGIC + _U32.pack(len(blob)) + blob)
        self.record(world, {})  # the initial state

    @property
    def frames_written(self) -> int:
        return self._frames

    def record(self, world: World, game_state: dict[str, Any]) -> None:
        self._game = game_state
        if world.sim_time_ms >= self._frames * self._period_ms:
            self._write(world.sim_time_ms, world.data.xpos, world.data.xquat)
            while self._frames * self._period_ms <= world.sim_time_ms:
                self._frames += 1

    def event(self, event: dict[str, Any]) -> None:
        self._events.append(event)

    def _write(self, sim_time_ms: int, xpos: np.ndarray, xquat: np.ndarray) -> None:
        if self._out is None:
            raise ValueError(f"{self.path}: recorder is closed")
        meta = _dumps({"game": self._game, "events": self._events})
        self._events = []
        poses = zlib.compress(np.concatenate([xpos, xquat], axis=1).astype("<f4").tobytes(), 6)
        payload = _FRAME_HEAD.pack(sim_time_ms, len(meta)) + meta + poses
        self._out.write(_U32.pack(len(payload)) + payload)
        self._last_time_ms = sim_time_ms

    def close(self, world: World | None = None) -> None:
        """Flush events not yet written (in a last frame when ``world`` is given) and close."""
        if self._out is None:
            return
        if self._events and world is not None and world.sim_time_ms != self._last_time_ms:
            self._write(world.sim_time_ms, world.data.xpos, world.data.xquat)
        self._out.close()
        self._out = None

    def __enter__(self) -> Recorder:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def _header(data: dict[str, Any]) -> ReplayHeader:
    return ReplayHeader(
        version=int(data["version"]),
        match_id=str(data["match_id"]),
        seed=int(data["seed"]),
        field_class=str(data["field_class"]),
        physics_dt_s=float(data["physics_dt_s"]),
        step_ms=int(data["step_ms"]),
        rate_hz=float(data["rate_hz"]),
        robots=tuple(
            RobotPlacement(
                id=RobotId(TeamColor(r["team"]), int(r["number"])),
                model=str(r["model"]),
                x_m=float(r["x_m"]),
                y_m=float(r["y_m"]),
                yaw_rad=float(r["yaw_rad"]),
            )
            for r in data["robots"]
        ),
        body_names=tuple(data["body_names"]),
    )


def load_replay(path: str | Path) -> Replay:
    """Read a whole replay; ReplayError names the file and the problem."""
    path = Path(path)
    try:
        blob = path.read_bytes()
    except OSError as exc:
        raise ReplayError(path=str(path), reason=f"cannot read: {exc}") from exc
    if not blob.startswith(MAGIC):
        raise ReplayError(path=str(path), reason="not an hlvsrec file (bad magic)")
    try:
        (size,) = _U32.unpack_from(blob, len(MAGIC))
        start = len(MAGIC) + 4
        raw = json.loads(blob[start : start + size])
        if raw.get("version") != FORMAT_VERSION:
            raise ReplayError(
                path=str(path), reason=f"version {raw.get('version')}, expected {FORMAT_VERSION}"
            )
        header = _header(raw)
        nbody = len(header.body_names)
        offset = start + size
        frames = []
        while offset < len(blob):
            (length,) = _U32.unpack_from(blob, offset)
            offset += 4
            time_ms, meta_len = _FRAME_HEAD.unpack_from(blob, offset)
            meta = json.loads(blob[offset + 8 : offset + 8 + meta_len])
            packed = blob[offset + 8 + meta_len : offset + length]
            poses = np.frombuffer(zlib.decompress(packed), dtype="<f4", count=nbody * 7)
            frames.append(
                ReplayFrame(
                    sim_time_ms=time_ms,
                    game=meta["game"],
                    events=meta["events"],
                    poses=poses.reshape(nbody, 7),
                )
            )
            offset += length
    except (struct.error, zlib.error, ValueError, KeyError, TypeError) as exc:
        raise ReplayError(path=str(path), reason=f"truncated or corrupt: {exc}") from exc
    return Replay(header=header, frames=tuple(frames))
