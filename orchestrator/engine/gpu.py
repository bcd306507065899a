"""Finding an NVIDIA GPU that the Docker engine can hand to a container (the ``gpu`` setting).

A GPU is usable when the host has NVIDIA device files (``/dev/nvidia0``, ``/dev/nvidiactl``)
and the engine can inject the driver into a container, which takes the NVIDIA container
toolkit: its ``nvidia`` runtime registered with the engine (``docker info``: ``Runtimes``), its
hook ``nvidia-container-runtime-hook`` on the path (the engine's ``--gpus`` device driver), or a
CDI specification of ``nvidia.com/gpu`` devices in one of the engine's ``CDISpecDirs``.
The device files are looked for on this host: with a remote engine the answer is "none".
Everything the check touches is injectable, so the decision is tested without a GPU.
"""

from __future__ import annotations

import glob
import logging
import os
import shutil
from collections.abc import Callable, Iterable, Mapping
from pathlib import Path
from typing import Any

from orchestrator.runtime.port import GpuDetection

log = logging.getLogger(__name__)

HOOK = "nvidia-container-runtime-hook"
CDI_KIND = "nvidia.com/gpu"
DEFAULT_CDI_DIRS = ("/etc/cdi", "/var/run/cdi")
DEVICE_PATTERN = "/dev/nvidia[0-9]*"
CONTROL_DEVICE = "/dev/nvidiactl"


def device_files(pattern: str = DEVICE_PATTERN, control: str = CONTROL_DEVICE
                 ) -> tuple[str, ...]:
    """The NVIDIA device files of this host (the control device last, only with a GPU)."""
    devices = sorted(glob.glob(pattern))
    return tuple(devices) + ((control,) if devices and os.path.exists(control) else ())


def _cdi_specs(dirs: Iterable[str]) -> tuple[str, ...]:
    """Specification files in ``dirs`` that declare NVIDIA GPU devices."""
    found = []
    for folder in dirs:
        for path in sorted(Path(folder).glob("*")):
            if path.suffix not in (".yaml", ".yml", ".json") or not path.is_file():
                continue
            try:
                if CDI_KIND in path.read_text(encoding="utf-8", errors="replace"):
                    found.append(str(path))
            except OSError:
                continue
    return tuple(found)


def detect(
    info: Mapping[str, Any] | None,
    *,
    devices: Callable[[], tuple[str, ...]] = device_files,
    which: Callable[[str], str | None] = shutil.which,
    cdi_specs: Callable[[Iterable[str]], tuple[str, ...]] = _cdi_specs,
    info_error: str = "",
) -> GpuDetection:
    """What this host offers, from the engine's ``docker info`` (None: not readable, see
    ``info_error``) and the device files."""
    files = devices()
    gpus = [f for f in files if f != CONTROL_DEVICE]
    if not gpus:
        return GpuDetection(access=None, reason="no NVIDIA device file (/dev/nvidia0, ...) on "
                            "this host")
    if CONTROL_DEVICE not in files:
        return GpuDetection(access=None, devices=files, reason=f"{CONTROL_DEVICE} is missing "
                            "(is the NVIDIA driver loaded?)")
    if info is None:
        return GpuDetection(access=None, devices=files,
                            reason=f"the Docker engine did not answer: {info_error}")
    runtimes = sorted((info.get("Runtimes") or {}).keys())
    if "nvidia" in runtimes:
        return GpuDetection(access="device-request", devices=files,
                            via="the engine's nvidia runtime")
    hook = which(HOOK)
    if hook:
        return GpuDetection(access="device-request", devices=files, via=hook)
    specs = cdi_specs(info.get("CDISpecDirs") or DEFAULT_CDI_DIRS)
    if specs:
        return GpuDetection(access="cdi", devices=files, via=f"CDI spec {specs[0]}")
    return GpuDetection(
        access=None, devices=files,
        reason=f"{', '.join(gpus)} present but the Docker engine cannot hand it to a container "
        f"(runtimes {', '.join(runtimes) or 'none'}, no {HOOK}, no CDI spec of {CDI_KIND}; "
        "install the NVIDIA container toolkit)")


def detect_nvidia(
    client: Any, *, devices: Callable[[], tuple[str, ...]] = device_files
) -> GpuDetection:
    """:func:`detect` on the engine of the Docker SDK ``client`` (asked only with a GPU)."""
    import docker.errors
    import requests.exceptions

    if not devices():
        return detect(None, devices=devices)
    try:
        info: Mapping[str, Any] | None = client.info()
        error = ""
    except (docker.errors.DockerException, requests.exceptions.RequestException, OSError) as exc:
        info, error = None, str(exc)
    found = detect(info, devices=devices, info_error=error)
    log.debug("GPU detection: %s", found)
    return found


__all__ = ["detect", "detect_nvidia", "device_files"]
