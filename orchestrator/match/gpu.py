"""Whether the simulator container gets the host's NVIDIA GPU for its cameras (``gpu``).

``gpu`` of game.json (or ``--gpu`` of ``hlvs match`` / ``hlvs scrimmage``):

- ``auto`` (default): the GPU when the host has one that Docker can hand to a container, else
  the CPU (OSMesa), said once in the log;
- ``on``: the GPU or no match (:class:`~orchestrator.errors.ConfigError` naming the option);
- ``off``: the CPU, the host is not even looked at.

With the GPU the simulator container gets every NVIDIA device (a Docker device request, as
``docker run --gpus all``), the driver's graphics libraries (``NVIDIA_DRIVER_CAPABILITIES``
with ``graphics``) and ``MUJOCO_GL=egl`` on EGL device :data:`EGL_DEVICE_ID`; ``HLVS_GPU`` tells
the simulator what was asked, so that it refuses a software renderer under ``on`` and falls
back to OSMesa under ``auto`` (:mod:`simulator.gl`). How a GPU is found on the host is the
adapter's business (:mod:`orchestrator.engine.gpu`); this module only decides.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from typing import Literal, get_args

from contracts import GPU_ENVIRONMENT  # what was asked (on | auto), read by the simulator
from orchestrator.errors import ConfigError, Problem
from orchestrator.runtime.port import (
    Access,
    ContainerRequest,
    DeviceRequest,
    GpuDetection,
    GpuProbe,
)

log = logging.getLogger(__name__)

GpuMode = Literal["auto", "on", "off"]
GPU_MODES: tuple[str, ...] = get_args(GpuMode)
DEFAULT_GPU_MODE: GpuMode = "auto"
# The first GPU the container sees: MuJoCo orders EGL devices by CUDA id when the driver tells
# it (NVIDIA's does), ahead of other EGL devices such as Mesa's software one.
EGL_DEVICE_ID = 0
DRIVER_CAPABILITIES = "graphics,compute,utility"  # graphics: the EGL/OpenGL driver libraries
CDI_ALL_GPUS = "nvidia.com/gpu=all"



@dataclass(frozen=True, slots=True, kw_only=True)
class GpuOrigin:
    """Where the ``gpu`` setting was written, for the error of ``on`` without a GPU."""

    file: str = "game.json"
    pointer: str = "/gpu"


@dataclass(frozen=True, slots=True, kw_only=True)
class SimulatorGpu:
    """The GPU granted to the simulator container."""

    mode: GpuMode
    access: Access
    devices: tuple[str, ...] = ()
    egl_device_id: int = EGL_DEVICE_ID

    def environment(self) -> dict[str, str]:
        return {
            "NVIDIA_VISIBLE_DEVICES": "all",
            "NVIDIA_DRIVER_CAPABILITIES": DRIVER_CAPABILITIES,
            "MUJOCO_GL": "egl",
            "PYOPENGL_PLATFORM": "egl",
            "MUJOCO_EGL_DEVICE_ID": str(self.egl_device_id),
            GPU_ENVIRONMENT: self.mode,
        }

    def device_requests(self) -> tuple[DeviceRequest, ...]:
        if self.access == "cdi":
            return (DeviceRequest(driver="cdi", device_ids=(CDI_ALL_GPUS,)),)
        return (DeviceRequest(count=-1, capabilities=(("gpu",),)),)

    def taken_from(self, request: ContainerRequest) -> ContainerRequest:
        """``request`` without this GPU: no device request, none of its environment."""
        mine = self.environment()
        return replace(
            request, device_requests=(),
            environment={k: v for k, v in request.environment.items() if k not in mine})


_said: set[str] = set()


def _once(message: str, *args: object) -> None:
    text = message % args
    if text not in _said:
        _said.add(text)
        log.info("%s", text)


def simulator_gpu(
    mode: str, probe: GpuProbe, *, origin: GpuOrigin | None = None
) -> SimulatorGpu | None:
    """The GPU for the simulator under ``mode``, None: cameras render on the CPU.

    Raises:
        ConfigError: ``mode`` is not one of :data:`GPU_MODES`, or ``on`` on a host without an
            NVIDIA GPU that Docker can use (the problem names where ``gpu`` was set).
    """
    origin = origin or GpuOrigin()
    if mode not in GPU_MODES:
        raise ConfigError([Problem(
            file=origin.file, pointer=origin.pointer, message=f"unknown value {mode!r}",
            expected=" or ".join(f'"{m}"' for m in GPU_MODES))])
    if mode == "off":
        return None
    found = probe()
    if found.access is None:
        if mode == "on":
            raise ConfigError([Problem(
                file=origin.file, pointer=origin.pointer,
                message=f'"on" but no NVIDIA GPU that Docker can use here: {found.reason}',
                expected='"auto" (the GPU when there is one, else the CPU) or "off", or a host '
                "with an NVIDIA GPU and the NVIDIA container toolkit")])
        _once("gpu auto: %s; the simulator renders cameras on the CPU (OSMesa)", found.reason)
        return None
    grant = SimulatorGpu(mode="on" if mode == "on" else "auto", access=found.access,
                         devices=found.devices)
    _once("gpu %s: the simulator gets the NVIDIA GPU (%s through %s), cameras through EGL",
          mode, ", ".join(found.devices) or "CDI devices", found.via or found.access)
    return grant


__all__ = [
    "DEFAULT_GPU_MODE",
    "GPU_ENVIRONMENT",
    "GPU_MODES",
    "GpuDetection",
    "GpuMode",
    "GpuOrigin",
    "GpuProbe",
    "SimulatorGpu",
    "simulator_gpu",
]
