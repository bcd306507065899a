"""What one robot's head camera saw, from a replay: ``hlvs render REPLAY --camera red-1 -o DIR``.

The replay's scene (:mod:`simulator.replay.scene`) carries the match's look, the robots' head
cameras (resolution and field of view) and the camera model; each frame's body poses place
the camera and the world, and every video frame becomes ``DIR/red-1_00000.png`` (RGB, the
camera's resolution), lit as the match was (the luminosity is in the lights), with the
match's exposure and per-pixel noise (motion blur needs the robots' velocities, which replays
do not keep). Imports nothing that imports MuJoCo at its top
(the offscreen back end is chosen first).
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from simulator.errors import ReplayError

if TYPE_CHECKING:
    from simulator.replay.format import RobotCameraRecord, SceneRecord


def _robot_camera(scene: SceneRecord, robot: str, path: str) -> RobotCameraRecord:
    cameras: dict[str, RobotCameraRecord] = {c["robot"]: c for c in scene.get("robot_cameras", ())}
    camera = cameras.get(robot)
    if camera is None:
        known = ", ".join(sorted(cameras)) or "none (a replay recorded before head cameras were"
        known += "" if cameras else " kept)"
        raise ReplayError(path=path, reason=f"no head camera of robot {robot!r}; cameras: {known}")
    return camera


def render_camera_frames(
    replay_path: str | Path,
    output_dir: str | Path,
    *,
    robot: str,
    fps: float = 25.0,
    ideal: bool = False,
    on_frame: Callable[[int, int], None] | None = None,
) -> list[Path]:
    """Write ``robot``'s camera frames (``red-1``) of a replay as PNG files into
    ``output_dir`` (created); ``ideal`` leaves out exposure and noise. Returns the files."""
    import mujoco
    import numpy as np

    from contracts import from_data
    from simulator.png import write_png
    from simulator.replay import load_replay, scene_for
    from simulator.scene_model import Placer, frames_for, scene_model
    from simulator.world.camera_model import CameraEffects, CameraModel
    from simulator.world.look import look_from_summary

    replay = load_replay(replay_path)
    scene = scene_for(replay.header, str(replay_path))
    camera = _robot_camera(scene, robot, str(replay_path))
    width, height = int(camera["width"]), int(camera["height"])
    model = scene_model(scene)
    recorded = scene.get("camera_model")
    camera_model = (
        from_data(CameraModel, recorded, source=str(replay_path), pointer="/scene/camera_model")
        if recorded and not ideal
        else CameraModel.ideal()
    )
    model.vis.global_.offwidth = max(model.vis.global_.offwidth, width)
    model.vis.global_.offheight = max(model.vis.global_.offheight, height)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    place = Placer(model, data)
    luminosity = look_from_summary(scene["look"]).luminosity if scene.get("look") else 1.0
    effects = CameraEffects(camera_model, width, height, luminosity=luminosity)
    number = int(robot.rsplit("-", 1)[1]) + (32 if robot.startswith("blue") else 0)
    out = Path(output_dir)
    out.mkdir(parents=True, exist_ok=True)
    renderer = mujoco.Renderer(model, height=height, width=width)
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
    option = mujoco.MjvOption()
    option.geomgroup[4] = 0
    indices = list(frames_for(replay, fps))
    written: list[Path] = []
    try:
        for k, i in enumerate(indices):
            frame = replay.frames[i]
            place(frame.poses.astype(np.float64))
            renderer.update_scene(data, camera=camera["name"], scene_option=option)
            bgr = effects.bgr_bytes(
                renderer.render(), robot=number, sim_time_ms=int(frame.sim_time_ms)
            )
            rgb = np.frombuffer(bgr, dtype=np.uint8).reshape(height, width, 3)[:, :, ::-1]
            written.append(write_png(out / f"{robot}_{k:05d}.png", np.ascontiguousarray(rgb)))
            if on_frame is not None:
                on_frame(k + 1, len(indices))
    finally:
        renderer.close()
    return written
