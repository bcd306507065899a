"""Replay files (``.hlvsrec``): what the bytes are, for every version a reader accepts.

Version 3 (written today; little-endian)::

    b"HLVSREC\\0"
    u32 header length, header JSON: format "hlvsrec", version 3, match_id, seed, field_class,
        physics_dt_s, step_ms, rate_hz, chunk_frames, robots [{team, number, model, x_m, y_m,
        yaw_rad}], body_names, scene (see simulator.replay.scene)
    records, each: u8 kind, u32 payload length, payload
      kind 1, chunk: u32 meta length, meta JSON {"times": [ms...], "games": [{...}...],
          "events": [[{...}...]...]}, then the poses (frames, bodies, 7: x y z qw qx qy qz in
          the world frame) as integers: positions in units of ``POSITION_UNIT_M`` (0.1 mm),
          quaternion components times ``QUATERNION_SCALE`` with qw >= 0; each frame but the
          chunk's first as the difference to the frame before; zig-zag coded as u32, bytes
          shuffled (all first bytes, then all second bytes...), zlib. About 3x smaller than
          version 2 on a real match.
      kind 2, index (last): JSON {"chunks": [[offset, first_ms, last_ms, frames]...],
          "events": [{..., "frame_ms"}...], "frames", "duration_ms"}
    trailer: u64 offset of the index record, b"HLVSIDX\\0"

A reader seeks to the trailer, reads the index and then only the chunks it needs. A file whose
writer died has no trailer; it is read by scanning its records (an unfinished last record is
dropped). Version 2 is the same but for the poses of a chunk: zlib of the byte-shuffled float32
values. Version 1 (no scene, no index, one zlib block per frame) is described in
:mod:`simulator.replay.reader`.

JSON is written with sorted keys and fixed separators and zlib at a fixed level, so a match
replayed from the same seed and inputs gives a byte-identical file (nothing measured on the
wall clock goes into it: API traffic and the real-time factor are in ``api_stats.jsonl``).
"""

from __future__ import annotations

import json
import struct
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, NotRequired, TypedDict

import numpy as np
import numpy.typing as npt

from contracts import EventRecord, GameStateRecord, JSONObject

if TYPE_CHECKING:  # the world's own record of its look (the world stays below the replay)
    from simulator.world.look import LookRecord

MAGIC = b"HLVSREC\0"
INDEX_MAGIC = b"HLVSIDX\0"
FORMAT_VERSION = 3
SUPPORTED_VERSIONS = (1, 2, 3)
POSITION_UNIT_M = 1e-4
QUATERNION_SCALE = 32767.0
CHUNK = 1
INDEX = 2
U32 = struct.Struct("<I")
RECORD_HEAD = struct.Struct("<BI")
TRAILER = struct.Struct("<Q8s")
POSE_WIDTH = 7


class PatternRecord(TypedDict):
    """A two-colour texture of a geom, drawn as stripes or checks by the viewer."""

    colors: list[list[float]]  # the two RGB colours
    repeat: list[float]
    cube: bool


class GeomRecord(TypedDict):
    name: str
    body: int
    type: str  # "plane" | "sphere" | "capsule" | "ellipsoid" | "cylinder" | "box"
    size: list[float]
    pos: list[float]
    quat: list[float]
    rgba: list[float]
    group: int
    texture: NotRequired[str]  # a look's material ("look:...")
    pattern: NotRequired[PatternRecord]


class SceneCameraRecord(TypedDict):
    """A fixed camera of the field (on the world body)."""

    name: str
    body: int
    pos: list[float]
    quat: list[float]
    fovy_deg: float


class RobotCameraRecord(SceneCameraRecord):
    """A robot's head camera."""

    robot: str  # robot key, "red-1"
    width: int
    height: int


class SceneRobotRecord(TypedDict):
    team: str
    number: int
    model: str
    root_body: int  # index of the robot's root body (-1: not found)


class SceneRecord(TypedDict):
    """What a viewer needs to draw a match (see :mod:`simulator.replay.scene`); replays of
    earlier versions lack the keys marked ``NotRequired``."""

    bodies: list[str]
    geoms: list[GeomRecord]
    cameras: list[SceneCameraRecord]
    robot_cameras: NotRequired[list[RobotCameraRecord]]
    robots: list[SceneRobotRecord]
    field: JSONObject  # contracts.field.FieldGeometry's fields
    look: NotRequired[LookRecord]
    camera_model: NotRequired[JSONObject | None]  # simulator.world.CameraModel (contracts.codec)


class HeaderRecord(TypedDict):
    """The header JSON of a replay (also the scene message sent to live viewers)."""

    format: str  # "hlvsrec"
    version: int
    match_id: str
    seed: int
    field_class: str
    physics_dt_s: float
    step_ms: int
    rate_hz: float
    chunk_frames: NotRequired[int]
    robots: list[JSONObject]  # each a RobotEntry (contracts.codec)
    body_names: list[str]
    scene: NotRequired[SceneRecord]  # versions 2 and 3


class ChunkMeta(TypedDict):
    """The JSON part of a chunk record: one entry per frame."""

    times: list[int]  # sim_time_ms
    games: list[GameStateRecord]
    events: list[list[EventRecord]]  # the referee events recorded with each frame


def dumps(value: object) -> bytes:
    return json.dumps(value, sort_keys=True, separators=(",", ":"), default=str).encode()


def shuffle(poses: npt.NDArray[np.float32]) -> bytes:
    """Byte-shuffle little-endian float32 values: all byte 0s, then byte 1s..."""
    raw = np.ascontiguousarray(poses, dtype="<f4").view(np.uint8).reshape(-1, 4)
    return raw.T.tobytes()


def unshuffle(blob: bytes, count: int) -> npt.NDArray[np.float32]:
    """Inverse of :func:`shuffle` for ``count`` float32 values."""
    planes = np.frombuffer(blob, dtype=np.uint8, count=count * 4).reshape(4, count)
    return np.ascontiguousarray(planes.T).view("<f4").reshape(count)


def encode_poses(poses: npt.NDArray[np.floating[Any]]) -> bytes:
    """Version 3 pose block of (frames, bodies, 7) poses, before zlib (see the docstring)."""
    values = np.asarray(poses, dtype=np.float64)
    quat = values[:, :, 3:7] * np.where(values[:, :, 3:4] < 0, -1.0, 1.0)
    ints = np.concatenate(
        [np.rint(values[:, :, :3] / POSITION_UNIT_M), np.rint(quat * QUATERNION_SCALE)], axis=2
    ).astype(np.int64)
    ints[1:] -= ints[:-1].copy()
    zigzag = ((ints << 1) ^ (ints >> 63)).astype("<u4")
    return zigzag.view(np.uint8).reshape(-1, 4).T.tobytes()


def decode_poses(blob: bytes, frames: int, bodies: int) -> npt.NDArray[np.float32]:
    """Inverse of :func:`encode_poses`: (frames, bodies, 7) float32 poses."""
    count = frames * bodies * POSE_WIDTH
    planes = np.frombuffer(blob, dtype=np.uint8, count=count * 4).reshape(4, count)
    zigzag = np.ascontiguousarray(planes.T).view("<u4").reshape(frames, bodies, POSE_WIDTH)
    z = zigzag.astype(np.int64)
    ints = np.cumsum((z >> 1) ^ -(z & 1), axis=0)
    out = np.empty((frames, bodies, POSE_WIDTH), dtype=np.float32)
    out[:, :, :3] = ints[:, :, :3] * POSITION_UNIT_M
    out[:, :, 3:] = ints[:, :, 3:] / QUATERNION_SCALE
    return out


@dataclass(frozen=True, slots=True, kw_only=True)
class RobotEntry:
    """A robot as the replay header lists it (team colour value, number, model, start pose):
    the header's ``robots`` entries are these, written and read by :mod:`contracts.codec`."""

    team: str
    number: int
    model: str
    x_m: float
    y_m: float
    yaw_rad: float

    @property
    def key(self) -> str:
        return f"{self.team}_{self.number}"


@dataclass(frozen=True, slots=True, kw_only=True)
class ReplayHeader:
    version: int
    match_id: str
    seed: int
    field_class: str
    physics_dt_s: float
    step_ms: int
    rate_hz: float
    robots: tuple[RobotEntry, ...]
    body_names: tuple[str, ...]
    scene: SceneRecord | None  # None for version 1 (see simulator.replay.scene_for)
    raw: HeaderRecord


@dataclass(frozen=True, slots=True, kw_only=True)
class ChunkRef:
    """Where a run of frames is: the file offset of its record (or of its first frame, v1)."""

    offset: int
    first_ms: int
    last_ms: int
    frames: int


@dataclass(frozen=True, slots=True, kw_only=True)
class FrameBlock:
    """Decoded frames of one chunk."""

    times_ms: npt.NDArray[np.int64]
    games: list[GameStateRecord]
    events: list[list[EventRecord]]
    poses: npt.NDArray[np.float32]  # (frames, bodies, 7)


@dataclass(frozen=True, slots=True, kw_only=True)
class ReplayFrame:
    sim_time_ms: int
    game: GameStateRecord
    events: list[EventRecord]
    poses: npt.NDArray[np.float32]  # (nbody, 7): x y z qw qx qy qz


@dataclass(frozen=True, slots=True, kw_only=True)
class Replay:
    header: ReplayHeader
    frames: tuple[ReplayFrame, ...]
