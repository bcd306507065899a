"""CPU and memory peaks of running containers, sampled in background threads."""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass

from orchestrator.errors import InfrastructureError
from orchestrator.runtime.port import ContainerRuntime

log = logging.getLogger(__name__)


@dataclass(slots=True)
class Peaks:
    cpu_percent: float = 0.0
    memory_bytes: int = 0
    samples: int = 0


class StatsMonitor:
    """One daemon thread per container follows its stats stream until the container stops."""

    def __init__(self, runtime: ContainerRuntime) -> None:
        self._runtime = runtime
        self._lock = threading.Lock()
        self._peaks: dict[str, Peaks] = {}
        self._threads: list[threading.Thread] = []

    def watch(self, key: str, container_id: str) -> None:
        with self._lock:
            self._peaks[key] = Peaks()
        thread = threading.Thread(
            target=self._follow, args=(key, container_id), name=f"stats-{key}", daemon=True
        )
        thread.start()
        self._threads.append(thread)

    def _follow(self, key: str, container_id: str) -> None:
        try:
            for sample in self._runtime.stats_stream(container_id):
                with self._lock:
                    peaks = self._peaks[key]
                    peaks.cpu_percent = max(peaks.cpu_percent, sample.cpu_percent)
                    peaks.memory_bytes = max(peaks.memory_bytes, sample.memory_bytes)
                    peaks.samples += 1
        except InfrastructureError as exc:
            log.debug("stats of %s ended: %s", key, exc)

    def peaks(self, key: str) -> Peaks:
        with self._lock:
            found = self._peaks.get(key, Peaks())
            return Peaks(found.cpu_percent, found.memory_bytes, found.samples)

    def join(self, timeout_s: float = 1.0) -> None:
        """Wait at most ``timeout_s`` in total for the threads (they are daemons)."""
        deadline = time.monotonic() + timeout_s
        for thread in self._threads:
            thread.join(timeout=max(0.0, deadline - time.monotonic()))


__all__ = ["Peaks", "StatsMonitor"]
