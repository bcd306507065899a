"""The HLVS robot API: protobuf messages, framing, the per-robot TCP server and its benchmark."""

from __future__ import annotations

from simulator.api.cameras import RenderWorker
from simulator.api.devices import DeviceWorld, FakeCameraRenderer, FakeDeviceWorld, robot_key
from simulator.api.endpoints import PlayerEndpoint, endpoints_from_spec
from simulator.api.framing import MAX_FRAME_BYTES, FrameDecoder, FramingError, encode_frame
from simulator.api.lockstep import wait_lockstep
from simulator.api.quota import NetworkQuota
from simulator.api.schedule import rendering_bandwidth_mb_s
from simulator.api.server import ApiServer, LockstepSettings, PortUnavailable
from simulator.api.session import RobotSession
from simulator.api.stepping import (
    AsyncStepping,
    LockstepStepping,
    PipelinedStepping,
    Stepping,
    stepping_for,
)

__all__ = [
    "MAX_FRAME_BYTES",
    "ApiServer",
    "AsyncStepping",
    "DeviceWorld",
    "FakeCameraRenderer",
    "FakeDeviceWorld",
    "FrameDecoder",
    "FramingError",
    "LockstepSettings",
    "LockstepStepping",
    "NetworkQuota",
    "PipelinedStepping",
    "PlayerEndpoint",
    "PortUnavailable",
    "RenderWorker",
    "RobotSession",
    "Stepping",
    "encode_frame",
    "endpoints_from_spec",
    "rendering_bandwidth_mb_s",
    "robot_key",
    "stepping_for",
    "wait_lockstep",
]
