"""The next basic step's first position stage, computed while the step thread waits.

``mj_step`` is ``mj_step1`` (kinematics, collisions, constraints, velocity terms: what the
state alone decides) then ``mj_step2`` (actuation, the solver, integration: what ``ctrl`` and
the actuators' gains change). In lockstep the step thread spends the time between a step's
measurement and its clients' answers waiting, and the next step's first ``mj_step1`` needs no
answer: :class:`PositionStage` computes it on a thread of its own (MuJoCo releases the
interpreter's lock while it computes) and :meth:`World.step` finishes the substep with
``mj_step2``. The result is the same to the bit (a test steps two worlds both ways): the
stage depends on the state only, and :meth:`PositionStage.finish` says it is stale (and the
step computes it again) when the positions, velocities or activations changed after it began.
Measured on the 8-robot kid world, one substep's ``mj_step1`` is about half of its ``mj_step``
(127 of 262 us of CPU on the development machine).
"""

from __future__ import annotations

import threading

import mujoco
import numpy as np


class PositionStage:
    """``mj_step1`` of one world's next substep on a worker thread: :meth:`start` after a
    step, :meth:`finish` before the next; nothing else may touch the world's ``MjData`` in
    between (the world's own methods call :meth:`finish` first)."""

    def __init__(self, model: mujoco.MjModel, data: mujoco.MjData, *,
                 inline: bool = False) -> None:
        """``inline``: :meth:`start` computes the stage on the calling thread (no worker)."""
        self.inline = inline
        self._model = model
        self._data = data
        self._go = threading.Event()
        self._done = threading.Event()
        self._running = False
        self._closed = False
        self._qpos = np.empty_like(data.qpos)
        self._qvel = np.empty_like(data.qvel)
        self._act = np.empty_like(data.act)
        self._thread: threading.Thread | None = None

    def start(self) -> None:
        """Begin the next substep's ``mj_step1`` (the caller has set the model's options that
        substep runs with)."""
        if self._running or self._closed:
            return
        if self.inline:
            self._snap()
            mujoco.mj_step1(self._model, self._data)
            self._running = True
            return
        if self._thread is None:
            self._thread = threading.Thread(target=self._work, name="position-stage",
                                            daemon=True)
            self._thread.start()
        self._snap()
        self._running = True
        self._go.set()

    def _snap(self) -> None:
        """The state the stage starts from (:meth:`finish` compares it)."""
        data = self._data
        np.copyto(self._qpos, data.qpos)
        np.copyto(self._qvel, data.qvel)
        np.copyto(self._act, data.act)

    def finish(self) -> bool:
        """Wait for a started stage; True when the world's data now holds ``mj_step1`` of its
        current state (False: none was started, or the state changed after it began)."""
        if not self._running:
            return False
        if not self.inline:
            self._done.wait()
            self._done.clear()
        self._running = False
        data = self._data
        return (np.array_equal(self._qpos, data.qpos) and np.array_equal(self._qvel, data.qvel)
                and np.array_equal(self._act, data.act))

    def close(self) -> None:
        """Finish any stage and end the worker thread."""
        self.finish()
        self._closed = True
        if self._thread is not None:
            self._go.set()
            self._thread.join(timeout=5)
            self._thread = None

    def _work(self) -> None:
        model, data, go, done = self._model, self._data, self._go, self._done
        while True:
            go.wait()
            go.clear()
            if self._closed:
                return
            try:
                mujoco.mj_step1(model, data)
            finally:
                done.set()
