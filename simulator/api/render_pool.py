"""Camera images rendered by worker processes (several cores, no shared interpreter lock).

A drop-in for :class:`simulator.api.cameras.RenderWorker` (same ``submit`` / ``completed`` /
``wake_fd`` / ``in_flight`` / ``close`` surface): each worker process gets a pickled copy of the
world model through its pipe at start, then per batch the joint state of the step the images
are due for (``qpos``, ``mocap_pos``, ``mocap_quat``) and its share of the batch's jobs (round
robin). It recomputes the kinematics and renders with :class:`simulator.world.CameraRenderer`;
the images come back through a pipe, read by one thread per worker on the parent side. Threads
in one process do not render in parallel (measured: two render threads were slower than one);
separate processes do, with a core each.

The workers are forked when this process is still fit for it (:func:`start_method`: no other
Python thread, no OpenGL context made, whose renderer threads a child would lack): they
inherit the imported modules and the world, where a spawned worker imports MuJoCo and the
simulator again (0.37 s) and takes the model through its pipe. Two workers of an 8-robot world
ready to render: 0.30-0.43 s and 0.53-0.79 s of their CPU forked, 1.18-1.48 s and 1.76-2.49 s
spawned, on the two CPUs a match's robots start on. Else they are spawned.
"""

from __future__ import annotations

import logging
import multiprocessing as mp
import os
import signal
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import TYPE_CHECKING, Any

from contracts import RobotId
from simulator.api.cameras import CompletedImages
from simulator.api.measurement import CameraJob

if TYPE_CHECKING:
    from simulator.world import World

log = logging.getLogger(__name__)


@dataclass(slots=True)
class _Batch:
    remaining: int


def _serve(conn: Connection, world: tuple[Any, ...] | None, others: list[Connection]) -> None:
    """Worker process body: take the world (model, cameras, camera model, look) and the
    cameras to make ready (robot, width, height: one of each size), render one frame with each
    (the OpenGL context, the textures and the shaders are made then, before the match needs
    an image), say so (a ``None`` job), then render jobs until ``None`` or the parent is
    gone. A forked worker has ``world`` already and closes ``others``, the parent's ends of
    the workers' pipes forked before it (so that each worker sees its parent go); a spawned
    one reads ``world`` from its pipe."""
    from types import SimpleNamespace

    import mujoco

    from simulator.world import CameraRenderer

    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the parent stops it, Ctrl-C or not
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # not a forked copy of the parent's handler
    for other in others:
        other.close()
    try:
        model, cameras, camera_model, look, warm = world if world is not None else conn.recv()
    except (EOFError, OSError):
        return
    data = mujoco.MjData(model)
    index = SimpleNamespace(by_id={r: SimpleNamespace(camera=c) for r, c in cameras.items()})
    view = SimpleNamespace(
        model=model, data=data, index=index, camera_model=camera_model, look=look
    )
    renderers: dict[tuple[int, int], CameraRenderer] = {}

    def renderer_for(width: int, height: int) -> CameraRenderer:
        renderer = renderers.get((width, height))
        if renderer is None:
            renderer = renderers[(width, height)] = CameraRenderer(
                view,  # type: ignore[arg-type]
                width,
                height,
            )
        return renderer

    if warm:
        mujoco.mj_kinematics(model, data)
        mujoco.mj_camlight(model, data)
    for robot, width, height in warm:
        renderer_for(width, height).render(robot, sim_time_ms=0)
    try:
        conn.send((None, None, 0.0))
    except OSError:
        return
    while True:
        try:
            message = conn.recv()
        except (EOFError, OSError):
            return
        if message is None:
            return
        qpos, mocap_pos, mocap_quat, qvel, sim_time_ms, jobs = message
        data.qpos[:] = qpos
        data.qvel[:] = qvel
        data.mocap_pos[:] = mocap_pos
        data.mocap_quat[:] = mocap_quat
        mujoco.mj_kinematics(model, data)
        mujoco.mj_camlight(model, data)
        for job_id, robot, width, height in jobs:
            started = time.perf_counter()
            image = renderer_for(width, height).render(robot, sim_time_ms=sim_time_ms)
            conn.send((job_id, image, time.perf_counter() - started))


def start_method() -> str:
    """``"fork"`` when this process may fork a render worker safely, else ``"spawn"``. Fit
    for it: a Linux process whose only Python thread is the main one and whose other threads
    (a BLAS library's, forked safely) all bear the process's name. Mesa names the threads of
    an OpenGL context (``llvmpipe-0``, ``python:disk$0``), and a child forked after a context
    was made would render with a rasterizer whose threads it lacks."""
    if threading.active_count() != 1 or "fork" not in mp.get_all_start_methods():
        return "spawn"
    try:
        tasks = os.listdir("/proc/self/task")
    except OSError:
        return "spawn"
    # a thread that ended between the listing and the look (a Python thread just joined
    # leaves the kernel a moment later) is no thread of the child's
    names = {name for task in tasks if (name := _thread_name(task)) is not None}
    return "fork" if len(names) == 1 and "" not in names else "spawn"


def _thread_name(task: str) -> str | None:
    """The thread's name, None when it has ended, "" when it cannot be read (not fit)."""
    try:
        with open(f"/proc/self/task/{task}/comm", encoding="utf-8", errors="replace") as comm:
            return comm.read().strip()
    except (FileNotFoundError, ProcessLookupError):
        return None
    except OSError:
        return ""


class RenderPool:
    """``processes`` rendering processes for ``world``'s head cameras."""

    def __init__(self, world: World, *, processes: int = 2, method: str | None = None) -> None:
        self._world = world
        self._count = max(1, processes)
        self._method = method  # "fork" or "spawn"; None: :func:`start_method` at the start
        self._cameras = {r.id: r.camera for r in world.index.robots}
        sizes: dict[tuple[int, int], RobotId] = {}
        for robot in self._cameras:
            width, height, _ = world.camera_info(robot)
            sizes.setdefault((width, height), robot)
        self._warm = [(robot, width, height) for (width, height), robot in sizes.items()]
        self.ready = 0  # processes that have made their renderers ready
        self._completed = CompletedImages()
        self._lock = threading.Lock()
        self._jobs: dict[int, tuple[_Batch, CameraJob]] = {}
        self._next_id = 0
        self._conns: list[Connection] = []
        self._procs: list[Any] = []
        self._readers: list[threading.Thread] = []
        self.error: BaseException | None = None
        self.frames = 0
        self.render_s = 0.0
        self._submitted = 0
        self._finished = 0
        self._closing = False
        self.start_method = ""  # "fork" or "spawn" once started

    @property
    def wake_fd(self) -> int:
        return self._completed.wake_fd

    def start(self) -> None:
        """Start the processes now (else at the first :meth:`submit`): each takes the world
        and renders a frame of every camera size, so that the first images of a match do
        not wait for that (on the CPU renderer the first eight 320x240 images took 2.3 s
        after a start at the first job, 40-46 ms after this one).
        :attr:`ready` counts those done."""
        if not self._procs:
            self._start()

    def _start(self) -> None:
        method = self._method or start_method()
        self.start_method = method
        forked = method == "fork"
        ctx = mp.get_context("fork") if forked else mp.get_context("spawn")
        world = (self._world.model, self._cameras, self._world.camera_model, self._world.look,
                 self._warm)  # fmt: skip
        for n in range(self._count):
            parent, child = ctx.Pipe()
            # spawned, the world goes through the pipe, not the process's arguments: a worker
            # that dies while it starts would leave the parent writing those to a pipe that
            # the parent itself still holds open (multiprocessing's spawn), waiting for ever
            args = (child, world, list(self._conns)) if forked else (child, None, [])
            proc = ctx.Process(target=_serve, args=args, name=f"camera-render-{n}", daemon=True)
            proc.start()
            child.close()
            if not forked:
                try:
                    parent.send(world)
                except OSError as exc:  # it died before it took the world: its jobs come back
                    log.error("camera render process %d did not start: %s", n, exc)  # black
                    self.error = exc
            self._conns.append(parent)
            self._procs.append(proc)
        log.info("robot cameras render in %d worker processes (%s)", self._count,
                 "forked" if forked else "spawned")  # fmt: skip
        for n, parent in enumerate(self._conns):  # threads only once every worker is forked
            reader = threading.Thread(
                target=self._collect, args=(parent,), name=f"camera-results-{n}", daemon=True
            )
            reader.start()
            self._readers.append(reader)

    def submit(self, jobs: Sequence[CameraJob]) -> None:
        self.start()
        data = self._world.data
        state = (data.qpos.copy(), data.mocap_pos.copy(), data.mocap_quat.copy(),
                 data.qvel.copy(), self._world.sim_time_ms)  # fmt: skip
        batch = _Batch(len(jobs))
        shares: list[list[tuple[int, RobotId, int, int]]] = [[] for _ in self._conns]
        with self._lock:
            self._submitted += 1
            for i, job in enumerate(jobs):
                job_id = self._next_id
                self._next_id += 1
                self._jobs[job_id] = (batch, job)
                shares[i % len(shares)].append((job_id, job.robot, job.width, job.height))
        for conn, share in zip(self._conns, shares, strict=True):
            if share:
                try:
                    conn.send((*state, share))
                except OSError as exc:  # the worker is gone: its jobs come back black
                    self._fail(exc, [job_id for job_id, *_ in share])

    @property
    def in_flight(self) -> int:
        with self._lock:
            return self._submitted - self._finished

    def completed(self) -> list[tuple[CameraJob, bytes]]:
        return self._completed.take()

    def _collect(self, conn: Connection) -> None:
        while True:
            try:
                job_id, image, seconds = conn.recv()
            except (EOFError, OSError) as exc:
                if not self._closing:  # a worker died: nothing may wait for it forever
                    with self._lock:
                        pending = list(self._jobs)
                    self._fail(exc, pending)
                return
            if job_id is None:  # the process has made its renderers
                with self._lock:
                    self.ready += 1
                continue
            self._deliver(job_id, image, seconds)

    def _deliver(self, job_id: int, image: bytes | None, seconds: float) -> None:
        with self._lock:
            entry = self._jobs.pop(job_id, None)
            if entry is None:
                return
            batch, job = entry
            self.frames += 1
            self.render_s += seconds
            batch.remaining -= 1
            if batch.remaining == 0:
                self._finished += 1
        self._completed.put(job, image if image is not None else bytes(job.width * job.height * 3))

    def _fail(self, exc: BaseException, job_ids: list[int]) -> None:
        log.error("camera render process failed: %s; black images", exc or "it exited")
        self.error = exc
        for job_id in job_ids:
            self._deliver(job_id, None, 0.0)

    def close(self) -> None:
        self._closing = True
        for conn in self._conns:
            try:
                conn.send(None)
            except OSError:
                pass  # already gone
        for proc in self._procs:
            proc.join(timeout=5.0)
            if proc.is_alive():
                proc.kill()
                proc.join(timeout=5.0)
        for conn in self._conns:
            conn.close()
        for reader in self._readers:
            reader.join(timeout=5.0)
        self._completed.close()
