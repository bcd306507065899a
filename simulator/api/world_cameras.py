"""Camera rendering for the real MuJoCo world, off the step thread.

``capture`` (step thread) copies the joint positions (and velocities, for motion blur) and the
simulated time of the step an image is due for; the
worker thread owns its own ``MjData`` and renderers, sets those positions, recomputes the
kinematics and renders with the world's :class:`~simulator.world.CameraRenderer`. The physics
state is never shared between threads.
"""

from __future__ import annotations

import os
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

from contracts import MAX_RENDER_PROCESSES, RobotId
from simulator.api.cameras import ImageSource, RenderFn, RenderWorker

if TYPE_CHECKING:
    from simulator.world import World

def render_processes() -> int:
    """Worker processes for a match's robot cameras: when they render offscreen (OSMesa on the
    CPU or EGL on a GPU) and this process may use two CPUs or more, one per CPU (at most
    :data:`MAX_RENDER_PROCESSES`); else 0, one render thread. A render thread shares the
    interpreter lock with the step thread (the camera model's numpy work holds it) and takes
    its turns beside the step, processes do not: on the 2-core development machine, 8 cameras
    at 320x240 every 32 ms, two processes played at real-time factors 0.60-0.74 in async
    stepping and 0.59-0.70 in lockstep where the thread gave 0.50-0.54 and 0.36-0.45 (three
    alternated pairs each); on an NVIDIA H200 with 16 CPUs (EGL, shadow map) four processes
    played at 2.00 and 2.11 where the thread gave 1.17 and 1.34 (lockstep, alternated)."""
    if os.environ.get("MUJOCO_GL", "") not in ("osmesa", "egl"):
        return 0
    cpus = len(os.sched_getaffinity(0))
    return min(cpus, MAX_RENDER_PROCESSES) if cpus >= 2 else 0


def world_render_worker(world: World, *, threads: int = 1, processes: int = 0) -> ImageSource:
    """Renderers for ``world``'s head cameras: ``processes`` > 0 gives a
    :class:`~simulator.api.render_pool.RenderPool` of that many processes, else ``threads``
    render threads in this process. One thread is the default: measured with OSMesa, a second
    thread lowered the total frame rate (46 -> 26 frames/s at 320x240)."""
    if processes > 0:
        from simulator.api.render_pool import RenderPool

        return RenderPool(world, processes=processes)

    def capture() -> Any:
        d = world.data
        return (d.qpos.copy(), d.mocap_pos.copy(), d.mocap_quat.copy(), d.qvel.copy(),
                world.sim_time_ms)  # fmt: skip

    def make_render() -> RenderFn:
        import mujoco

        from simulator.world import CameraRenderer

        model = world.model
        data = mujoco.MjData(model)
        view = SimpleNamespace(
            model=model, data=data, index=world.index, camera_model=world.camera_model,
            look=world.look,
        )
        renderers: dict[tuple[int, int], CameraRenderer] = {}
        current: list[Any] = [None]

        def render(state: Any, robot: RobotId, width: int, height: int) -> bytes:
            if state is not current[0]:
                qpos, mocap_pos, mocap_quat, qvel, _ = state
                data.qpos[:] = qpos
                data.qvel[:] = qvel
                data.mocap_pos[:] = mocap_pos
                data.mocap_quat[:] = mocap_quat
                mujoco.mj_kinematics(model, data)
                mujoco.mj_camlight(model, data)
                current[0] = state
            renderer = renderers.get((width, height))
            if renderer is None:
                renderer = CameraRenderer(view, width, height)  # type: ignore[arg-type]
                renderers[(width, height)] = renderer
            return renderer.render(robot, sim_time_ms=state[4])

        return render

    return RenderWorker(capture=capture, make_render=make_render, threads=threads)
