"""Replay files: the format (versions 1 and 2), reading with seeking, and the scene they carry.

The writer is :class:`simulator.recorder.Recorder` (it needs the MuJoCo world); reading needs
neither MuJoCo nor the world, except for a version 1 replay, whose scene is rebuilt from
today's robot models by :func:`scene_for`.
"""

from __future__ import annotations

from simulator.replay.format import (
    FORMAT_VERSION,
    SUPPORTED_VERSIONS,
    ChunkRef,
    FrameBlock,
    GeomRecord,
    HeaderRecord,
    Replay,
    ReplayFrame,
    ReplayHeader,
    RobotEntry,
    SceneRecord,
)
from simulator.replay.reader import ReplayFile, load_replay
from simulator.replay.scene import scene_for, scene_of

__all__ = [
    "FORMAT_VERSION",
    "SUPPORTED_VERSIONS",
    "ChunkRef",
    "FrameBlock",
    "GeomRecord",
    "HeaderRecord",
    "Replay",
    "ReplayFile",
    "ReplayFrame",
    "ReplayHeader",
    "RobotEntry",
    "SceneRecord",
    "load_replay",
    "scene_for",
    "scene_of",
]
