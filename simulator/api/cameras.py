"""Camera images rendered off the step thread.

The step thread captures the world state of the step a camera image is due for
(``capture()``, e.g. a copy of MuJoCo's ``qpos``) and hands it with the jobs to one worker
thread, which owns the OpenGL context (``make_render()`` is called inside the worker; OSMesa and
EGL contexts are bound to the thread that created them). Physics and the measurements of robots
without cameras do not wait for an image; the camera robot's measurements wait, in order. At most
:data:`MAX_IN_FLIGHT` batches are queued: when rendering cannot keep up with the requested
periods, the step loop waits for it (the real-time factor drops, memory and latency stay bounded).
"""

from __future__ import annotations

import logging
import os
import queue
import threading
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, Protocol

from contracts import RobotId
from simulator.api.measurement import CameraJob

log = logging.getLogger(__name__)

RenderFn = Callable[[Any, RobotId, int, int], bytes]
MAX_IN_FLIGHT = 2


class ImageSource(Protocol):
    """What the server needs from a renderer: :class:`RenderWorker` or a render pool."""

    error: BaseException | None
    frames: int
    render_s: float

    @property
    def wake_fd(self) -> int: ...

    @property
    def in_flight(self) -> int: ...

    def start(self) -> None: ...

    def submit(self, jobs: Sequence[CameraJob]) -> None: ...

    def completed(self) -> list[tuple[CameraJob, bytes]]: ...

    def close(self) -> None: ...


@dataclass(slots=True)
class _Batch:
    state: Any
    remaining: int


class CompletedImages:
    """Finished camera jobs handed from rendering threads to the step thread.

    ``put`` queues an image and writes a wake-up byte to a non-blocking pipe whose read end
    (:attr:`wake_fd`) the step loop polls; ``take`` drains both.
    """

    def __init__(self) -> None:
        self._done: queue.Queue[tuple[CameraJob, bytes]] = queue.Queue()
        self._read_fd, self._write_fd = os.pipe()
        os.set_blocking(self._read_fd, False)
        os.set_blocking(self._write_fd, False)

    @property
    def wake_fd(self) -> int:
        return self._read_fd

    def put(self, job: CameraJob, image: bytes) -> None:
        self._done.put((job, image))
        try:
            os.write(self._write_fd, b"x")
        except BlockingIOError:
            pass  # the pipe is full of wake-ups already

    def take(self) -> list[tuple[CameraJob, bytes]]:
        try:
            os.read(self._read_fd, 4096)
        except BlockingIOError:
            pass
        done: list[tuple[CameraJob, bytes]] = []
        while True:
            try:
                done.append(self._done.get_nowait())
            except queue.Empty:
                return done

    def close(self) -> None:
        os.close(self._read_fd)
        os.close(self._write_fd)


class RenderWorker:
    """Rendering threads (``threads``, each with its own GL context); completed jobs are
    collected on the step thread with :meth:`completed` when :attr:`wake_fd` is readable."""

    def __init__(
        self,
        *,
        capture: Callable[[], Any],
        make_render: Callable[[], RenderFn],
        threads: int = 1,
    ) -> None:
        self._capture = capture
        self._make_render = make_render
        self._count = max(1, threads)
        self._inbox: queue.Queue[tuple[_Batch, CameraJob] | None] = queue.Queue()
        self._completed = CompletedImages()
        self._threads: list[threading.Thread] = []
        self._lock = threading.Lock()
        self.error: BaseException | None = None
        self.frames = 0
        self.render_s = 0.0
        self._submitted = 0
        self._finished = 0  # batches, updated under the lock by the render threads

    @property
    def wake_fd(self) -> int:
        """Readable when completed jobs are waiting."""
        return self._completed.wake_fd

    def start(self) -> None:
        """Start the render threads now (else at the first :meth:`submit`): each makes its
        OpenGL context when it starts."""
        if not self._threads:
            for n in range(self._count):
                thread = threading.Thread(target=self._run, name=f"camera-render-{n}", daemon=True)
                thread.start()
                self._threads.append(thread)

    def submit(self, jobs: Sequence[CameraJob]) -> None:
        self.start()
        batch = _Batch(self._capture(), len(jobs))
        self._submitted += 1
        for job in jobs:
            self._inbox.put((batch, job))

    @property
    def in_flight(self) -> int:
        """Batches submitted and not completely rendered yet."""
        with self._lock:
            return self._submitted - self._finished

    def completed(self) -> list[tuple[CameraJob, bytes]]:
        return self._completed.take()

    def _run(self) -> None:
        import time

        try:
            render: RenderFn | None = self._make_render()
        except BaseException as exc:  # reported to the step thread through .error
            log.error("camera renderer could not start: %s", exc)
            self.error = exc
            render = None
        while True:
            item = self._inbox.get()
            if item is None:
                return
            batch, job = item
            started = time.perf_counter()
            image = bytes(job.width * job.height * 3)
            if render is not None:
                try:
                    image = render(batch.state, job.robot, job.width, job.height)
                except BaseException as exc:  # reported, then black frames
                    log.error("camera rendering failed for %s: %s", job.robot, exc)
                    self.error = exc
                    render = None
            with self._lock:
                self.render_s += time.perf_counter() - started
                self.frames += 1
                batch.remaining -= 1
                if batch.remaining == 0:
                    self._finished += 1
            self._completed.put(job, image)

    def close(self) -> None:
        for _ in self._threads:
            self._inbox.put(None)
        for thread in self._threads:
            thread.join(timeout=5.0)
        self._completed.close()
