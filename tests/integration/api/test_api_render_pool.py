"""Camera images from render processes match the in-process renderer; a dead worker gives
black images instead of a step loop waiting forever."""

from __future__ import annotations

import json
import os
import select
import subprocess
import sys
import time
from pathlib import Path

import mujoco
import numpy as np
import pytest

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import render_pool
from simulator.api.measurement import CameraJob
from simulator.api.render_pool import RenderPool
from simulator.world import CameraRenderer, RobotPlacement, World

RED_1, BLUE_1 = RobotId(TeamColor.RED, 1), RobotId(TeamColor.BLUE, 1)


@pytest.fixture(autouse=True)
def _offscreen(monkeypatch: pytest.MonkeyPatch) -> None:
    if not os.environ.get("DISPLAY"):
        monkeypatch.setenv("MUJOCO_GL", os.environ.get("MUJOCO_GL", "osmesa"))
        monkeypatch.setenv("PYOPENGL_PLATFORM", os.environ.get("MUJOCO_GL", "osmesa"))


def _world() -> World:
    placements = [
        RobotPlacement(id=RED_1, model="kid-default", x_m=-1.0, y_m=0.0, yaw_rad=0.0),
        RobotPlacement(id=BLUE_1, model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=3.14159),
    ]
    world = World.create(field_class="kid", robots=placements, seed=3)
    for _ in range(10):
        world.step()
    # after a step the poses are those of the step's start; the robots still settle into the
    # grass, so the kinematics of the state handed to the workers are computed here too
    mujoco.mj_kinematics(world.model, world.data)
    mujoco.mj_camlight(world.model, world.data)
    return world


def _jobs(time_ms: int) -> list[CameraJob]:
    return [
        CameraJob(robot, "Camera", 320, 240, time_ms, pb.CameraMeasurement())
        for robot in (RED_1, BLUE_1)
    ]


def _collect(pool: RenderPool, count: int) -> dict[RobotId, bytes]:
    images: dict[RobotId, bytes] = {}
    deadline = time.monotonic() + 60
    while len(images) < count and time.monotonic() < deadline:
        select.select([pool.wake_fd], [], [], 0.5)
        images.update((job.robot, image) for job, image in pool.completed())
    return images


def test_pool_images_equal_in_process_rendering() -> None:
    world = _world()
    with CameraRenderer(world, 320, 240) as local:
        expected = {robot: local.render(robot) for robot in (RED_1, BLUE_1)}
    pool = RenderPool(world, processes=2)
    try:
        pool.submit(_jobs(world.sim_time_ms))
        images = _collect(pool, 2)
        assert pool.in_flight == 0 and pool.frames == 2 and pool.error is None
    finally:
        pool.close()
    assert set(images) == {RED_1, BLUE_1}
    for robot in (RED_1, BLUE_1):  # the same picture (kinematics recomputed from qpos)
        got = np.frombuffer(images[robot], dtype=np.uint8).astype(int)
        want = np.frombuffer(expected[robot], dtype=np.uint8).astype(int)
        assert got.shape == want.shape
        assert np.mean(got != want) < 0.002  # a few edge pixels differ
    assert images[RED_1] != images[BLUE_1]


def test_dead_worker_gives_black_images() -> None:
    world = _world()
    pool = RenderPool(world, processes=1)
    try:
        pool.submit(_jobs(world.sim_time_ms))
        assert len(_collect(pool, 2)) == 2
        pool._procs[0].kill()  # noqa: SLF001 - the failure under test
        pool._procs[0].join(timeout=10)
        pool.submit(_jobs(world.sim_time_ms + 8))
        images = _collect(pool, 2)
        assert images and all(image == bytes(320 * 240 * 3) for image in images.values())
        assert pool.error is not None and pool.in_flight == 0
    finally:
        pool.close()


@pytest.mark.parametrize("method", ["spawn", "fork"])
def test_a_worker_that_dies_while_it_starts_gives_black_images(
    method: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A worker that dies while it starts, before it took the world (the kernel's OOM killer
    could do that): the pool does not wait for it (it used to wait for ever, writing the world
    into a pipe it held open itself), its images come back black and the error is kept. A
    spawned worker dies in its new interpreter, a forked one as it begins."""
    if method == "spawn":
        (tmp_path / "sitecustomize.py").write_text("import os\nos._exit(1)\n")  # every new one
        monkeypatch.setenv("PYTHONPATH", os.pathsep.join([str(tmp_path), *sys.path]))
    else:
        monkeypatch.setattr(render_pool, "_serve", lambda *_args: os._exit(1))
    world = _world()
    pool = RenderPool(world, processes=2, method=method)
    try:
        pool.submit(_jobs(world.sim_time_ms))
        images = _collect(pool, 2)
        assert set(images) == {RED_1, BLUE_1}
        assert all(image == bytes(320 * 240 * 3) for image in images.values())
        assert pool.error is not None and pool.in_flight == 0
    finally:
        pool.close()


def test_started_pool_makes_its_renderers_before_the_first_job() -> None:
    """``start()`` (a match calls it before the robots connect): every process takes the
    world and renders a frame of each camera size before any job, says so (``ready``), and
    its images are then the same as a pool started by its first job."""
    world = _world()
    pool = RenderPool(world, processes=2)
    try:
        pool.start()
        deadline = time.monotonic() + 60
        while pool.ready < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert pool.ready == 2 and pool.frames == 0 and pool.in_flight == 0
        pool.submit(_jobs(world.sim_time_ms))
        images = _collect(pool, 2)
        assert pool.frames == 2 and pool.error is None
    finally:
        pool.close()
    with CameraRenderer(world, 320, 240) as local:
        for robot in (RED_1, BLUE_1):
            got = np.frombuffer(images[robot], dtype=np.uint8).astype(int)
            want = np.frombuffer(local.render(robot), dtype=np.uint8).astype(int)
            assert np.mean(got != want) < 0.002  # a few edge pixels differ, as above


_FORK_PROBE = """
import json, threading
import numpy as np
from simulator.api import render_pool
from tests.integration.api import test_api_render_pool as t
from simulator.world import CameraRenderer

found = {"fresh": render_pool.start_method()}
world = t._world()
pool = render_pool.RenderPool(world, processes=2)
try:
    pool.submit(t._jobs(world.sim_time_ms))
    images = t._collect(pool, 2)
    found["pool"] = pool.start_method
finally:
    pool.close()
stop = threading.Event()
thread = threading.Thread(target=stop.wait)
thread.start()
found["with a thread"] = render_pool.start_method()
stop.set()
thread.join()
found["thread ended"] = render_pool.start_method()
with CameraRenderer(world, 320, 240) as local:  # an OpenGL context, made after the fork
    found["differ"] = {
        str(robot): float(np.mean(np.frombuffer(images[robot], np.uint8)
                                  != np.frombuffer(local.render(robot), np.uint8)))
        for robot in (t.RED_1, t.BLUE_1)
    }
found["after a context"] = render_pool.start_method()
print(json.dumps(found))
"""


def test_forked_workers_of_a_fresh_process_render_the_in_process_images() -> None:
    """A process with one thread and no OpenGL context forks its render workers (they inherit
    the world, no imports again); their images are the in-process renderer's. Another Python
    thread, or the threads of an OpenGL context made in the process, make it spawn them."""
    root = Path(__file__).resolve().parents[3]
    env = {**os.environ, "PYTHONPATH": str(root)}
    env.setdefault("MUJOCO_GL", "osmesa")
    env.setdefault("PYOPENGL_PLATFORM", env["MUJOCO_GL"])
    done = subprocess.run([sys.executable, "-c", _FORK_PROBE], cwd=root, env=env,
                          capture_output=True, text=True, timeout=120, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found["fresh"] == "fork" and found["pool"] == "fork", found
    assert found["with a thread"] == "spawn" and found["thread ended"] == "fork", found
    assert found["after a context"] == "spawn", found
    assert all(share < 0.002 for share in found["differ"].values()), found  # edge pixels
