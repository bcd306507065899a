"""Videos from replays: ``python -m simulator render REPLAY -o match.mp4 [--width --height --fps]``
(``--camera red-1 -o DIR``: that robot's camera frames as PNG, :mod:`simulator.camera_frames`).

A model of shapes only is built from the scene the replay carries (for a version 1 replay, from
today's robot models); each frame's body poses are turned into geom poses (no physics) and
drawn offscreen from the ``overview`` camera, and the raw RGB frames are
piped to ffmpeg (libx264, yuv420p). The game state of the frames (state, half, time left, score)
becomes a subtitle track. The offscreen OpenGL back end is chosen by :mod:`simulator.gl` before
MuJoCo is imported (``egl``, then ``osmesa``; a ``MUJOCO_GL`` set by the user is kept), so this
module imports nothing that imports MuJoCo at its top.
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import TYPE_CHECKING, Any

from simulator.errors import OffscreenGLError, RenderError, ReplayError
from simulator.gl import choose_offscreen_gl

if TYPE_CHECKING:  # numpy, MuJoCo and the replay reader are imported after the arguments
    import numpy as np
    import numpy.typing as npt

    from contracts import GameStateRecord
    from simulator.replay import Replay
    from simulator.replay.format import GeomRecord, SceneRecord

    Array = npt.NDArray[np.float64]

logger = logging.getLogger(__name__)


def _quat_to_mat(q: Array) -> Array:
    """(n, 4) w x y z -> (n, 3, 3) rotation matrices."""
    import numpy as np

    q = q / np.linalg.norm(q, axis=1, keepdims=True)
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack(
        [
            1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y),
        ],
        axis=1,
    ).reshape(-1, 3, 3)  # fmt: skip


class Placer:
    """Puts the bodies, geoms and cameras of a :func:`scene_model` at a frame's body poses
    (``(n, 7)``: x y z, w x y z), as MuJoCo's kinematics would (the model has no joints)."""

    def __init__(self, model: Any, data: Any) -> None:
        self._data = data
        self._geom_body = model.geom_bodyid.copy()
        self._geom_pos = model.geom_pos.copy()
        self._geom_rot = _quat_to_mat(model.geom_quat.copy())
        self._cam_body = model.cam_bodyid.copy()
        self._cam_pos = model.cam_pos.copy()
        self._cam_rot = _quat_to_mat(model.cam_quat.copy())

    def __call__(self, poses: Array) -> None:
        import numpy as np

        data = self._data
        body_rot = _quat_to_mat(poses[:, 3:7])
        rot = body_rot[self._geom_body]
        data.xpos[:] = poses[:, 0:3]
        data.xmat[:] = body_rot.reshape(-1, 9)
        data.geom_xpos[:] = poses[self._geom_body, 0:3] + np.einsum(
            "nij,nj->ni", rot, self._geom_pos
        )
        data.geom_xmat[:] = np.matmul(rot, self._geom_rot).reshape(-1, 9)
        if len(self._cam_body):
            cam_rot = body_rot[self._cam_body]
            data.cam_xpos[:] = poses[self._cam_body, 0:3] + np.einsum(
                "nij,nj->ni", cam_rot, self._cam_pos
            )
            data.cam_xmat[:] = np.matmul(cam_rot, self._cam_rot).reshape(-1, 9)


def _frames_for(replay: Replay, fps: float) -> Iterator[int]:
    """Index of the replay frame to show for each video frame at ``fps``."""
    frames = replay.frames
    if not frames:
        return
    end_ms = frames[-1].sim_time_ms
    k, i = 0, 0
    while k * 1000.0 / fps <= end_ms + 1e-6:
        t = k * 1000.0 / fps
        while i + 1 < len(frames) and frames[i + 1].sim_time_ms <= t + 1e-6:
            i += 1
        yield i
        k += 1


def caption(game: GameStateRecord) -> str:
    """One line about a frame's game state: ``PLAYING  1st half  09:58  red 1 : 0 blue``."""
    parts = []
    if game.get("state"):
        parts.append(str(game["state"]))
    if game.get("half") in (1, 2):
        parts.append("1st half" if game["half"] == 1 else "2nd half")
    secs = game.get("secs_remaining")
    if isinstance(secs, int | float):
        parts.append(f"{int(secs) // 60:02d}:{int(secs) % 60:02d}")
    score = game.get("score")
    if isinstance(score, dict) and "red" in score and "blue" in score:
        parts.append(f"red {score['red']} : {score['blue']} blue")
    return "  ".join(parts)


def _srt_time(seconds: float) -> str:
    ms = int(round(seconds * 1000))
    return f"{ms // 3600000:02d}:{ms // 60000 % 60:02d}:{ms // 1000 % 60:02d},{ms % 1000:03d}"


def _subtitles(replay: Replay, indices: list[int], fps: float) -> str:
    """SRT cues of the captions, one per run of video frames with the same caption."""
    cues: list[str] = []
    start = 0
    for k in range(1, len(indices) + 1):
        text = caption(replay.frames[indices[start]].game)
        if k < len(indices) and caption(replay.frames[indices[k]].game) == text:
            continue
        if text:
            cues.append(
                f"{len(cues) + 1}\n{_srt_time(start / fps)} --> {_srt_time(k / fps)}\n{text}\n"
            )
        start = k
    return "\n".join(cues)


def _f(values: list[float]) -> str:
    return " ".join(f"{v:.6g}" for v in values)


def _geom_xml(geom: GeomRecord, material: str | None) -> str:
    look = f'material="{material}"' if material else f'rgba="{_f(geom["rgba"])}"'
    return (
        f'<geom type="{geom["type"]}" size="{_f(geom["size"])}" pos="{_f(geom["pos"])}" '
        f'quat="{_f(geom["quat"])}" {look} group="{geom["group"]}" contype="0" '
        f'conaffinity="0"/>'
    )


def scene_xml(scene: SceneRecord) -> str:
    """An MJCF of shapes only (no joints, no physics) with one body per recorded body, in the
    recorded order, so that body ``i`` of the model is body ``i`` of every frame."""
    from simulator.world.look import look_assets, look_from_summary

    bodies = scene["bodies"]
    geoms: list[list[str]] = [[] for _ in bodies]
    if scene.get("look") is not None:  # the match's look (textures filled by ``scene_model``)
        assets = [look_assets(look_from_summary(scene["look"]))]
    else:
        assets = [
            '<texture name="sky" type="skybox" builtin="gradient" rgb1="0.55 0.7 0.9" '
            'rgb2="0.1 0.15 0.25" width="64" height="64"/>'
        ]
    for i, geom in enumerate(scene["geoms"]):
        material = geom.get("texture") if scene.get("look") is not None else None
        pattern = geom.get("pattern")
        if pattern is not None:
            material = f"m{i}"
            first, second = pattern["colors"]
            kind = "cube" if pattern["cube"] else "2d"
            assets.append(
                f'<texture name="t{i}" type="{kind}" builtin="checker" rgb1="{_f(first)}" '
                f'rgb2="{_f(second)}" width="64" height="64"/>'
                f'<material name="{material}" texture="t{i}" texrepeat="{_f(pattern["repeat"])}" '
                f'reflectance="0"/>'
            )
        geoms[geom["body"]].append(_geom_xml(geom, material))
    cameras = "".join(
        f'<camera name="{c["name"]}" pos="{_f(c["pos"])}" quat="{_f(c["quat"])}" '
        f'fovy="{c["fovy_deg"]:.6g}"/>'
        for c in scene["cameras"]
    )
    body_cameras: list[list[str]] = [[] for _ in bodies]
    for c in scene.get("robot_cameras", ()):
        body_cameras[c["body"]].append(
            f'<camera name="{c["name"]}" pos="{_f(c["pos"])}" quat="{_f(c["quat"])}" '
            f'fovy="{c["fovy_deg"]:.6g}"/>'
        )
    children = "".join(
        f'<body name="b{i}">{"".join(geoms[i])}{"".join(body_cameras[i])}</body>'
        for i in range(1, len(bodies))
    )
    return f"""<mujoco model="replay">
<visual>
 <global offwidth="1920" offheight="1080"/>
 <quality shadowsize="2048" offsamples="0"/>
 <headlight ambient="0.35 0.35 0.35" diffuse="0.3 0.3 0.3" specular="0 0 0"/>
 <map znear="0.01" zfar="100"/>
</visual>
<asset>{"".join(assets)}</asset>
<worldbody>
<light directional="true" pos="0 0 10" dir="0.2 0.3 -1" diffuse="0.7 0.7 0.7" castshadow="false"/>
<light directional="true" pos="0 0 10" dir="-0.2 -0.3 -1" diffuse="0.3 0.3 0.3" castshadow="false"/>
{cameras}{"".join(geoms[0])}{children}
</worldbody>
</mujoco>"""


def scene_model(scene: SceneRecord) -> Any:
    """The compiled :func:`scene_xml` of ``scene``, with its look's textures and lights."""
    import mujoco

    from simulator.world.look import apply_look, look_from_summary

    model = mujoco.MjModel.from_xml_string(scene_xml(scene))
    if scene.get("look") is not None:
        apply_look(model, look_from_summary(scene["look"]))
    return model


def render_video(
    replay_path: str | Path,
    output: str | Path,
    *,
    width: int = 1280,
    height: int = 720,
    fps: float = 25.0,
    on_frame: Callable[[int, int], None] | None = None,
) -> Path:
    """Render a replay file to an MP4 video; returns the output path.

    ``on_frame(done, total)`` is called after each frame (for a progress display).
    """
    import mujoco
    import numpy as np

    from simulator.replay import load_replay, scene_for

    output = Path(output)
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        raise RenderError(output=str(output), reason="ffmpeg not found on PATH")
    replay = load_replay(replay_path)
    from simulator.world.look import apply_luminosity, look_from_summary

    scene = scene_for(replay.header, str(replay_path))
    model = scene_model(scene)
    luminosity = look_from_summary(scene["look"]).luminosity if scene.get("look") else 1.0
    if model.nbody != len(replay.header.body_names):
        raise ReplayError(
            path=str(replay_path),
            reason=f"{len(replay.header.body_names)} bodies recorded, the scene has {model.nbody}",
        )
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    place = Placer(model, data)
    renderer = mujoco.Renderer(model, height=height, width=width)
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
    option = mujoco.MjvOption()
    option.geomgroup[4] = 0
    indices = list(_frames_for(replay, fps))
    command = [
        ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
        "-s", f"{width}x{height}", "-r", f"{fps:g}", "-i", "-",
    ]  # fmt: skip
    subtitles = _subtitles(replay, indices, fps)
    srt = output.with_name(output.name + ".srt")
    if subtitles:
        srt.write_text(subtitles, encoding="utf-8")
        command += ["-i", str(srt), "-map", "0:v", "-map", "1:s", "-c:s", "mov_text"]
    command += ["-c:v", "libx264", "-preset", "veryfast", "-pix_fmt", "yuv420p", str(output)]
    proc = subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdin is not None
    count = 0
    try:
        for i in indices:
            place(replay.frames[i].poses.astype(np.float64))
            renderer.update_scene(data, camera="overview", scene_option=option)
            proc.stdin.write(apply_luminosity(renderer.render(), luminosity).tobytes())
            count += 1
            if on_frame is not None:
                on_frame(count, len(indices))
        proc.stdin.close()
    except BrokenPipeError:
        pass
    finally:
        renderer.close()
    stderr = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
    code = proc.wait()
    srt.unlink(missing_ok=True)
    if code != 0:
        raise RenderError(output=str(output), reason=f"ffmpeg exited {code}: {stderr.strip()}")
    logger.info("rendered %d frames of %s to %s", count, replay_path, output)
    return output


@contextmanager
def _frame_progress(description: str) -> Iterator[Callable[[int, int], None]]:
    """A rich progress bar on a terminal; otherwise a plain line every 10 s and at the end
    (``HLVS_PROGRESS=plain|rich|off`` to choose, as for the other commands)."""
    mode = os.environ.get("HLVS_PROGRESS", "auto").lower()
    if mode == "auto":
        mode = "rich" if sys.stderr.isatty() and os.environ.get("TERM") != "dumb" else "plain"
    if mode == "off":
        yield lambda done, total: None
        return
    if mode == "rich":
        from rich.console import Console
        from rich.progress import Progress

        with Progress(console=Console(file=sys.stderr)) as bars:
            task = bars.add_task(description, total=None)
            yield lambda done, total: bars.update(task, completed=done, total=total)
        return
    last = [time.monotonic()]

    def line(done: int, total: int) -> None:
        now = time.monotonic()
        if now - last[0] >= 10.0 or done == total:
            last[0] = now
            print(f"{description}: {done} of {total} frames ({100 * done / max(total, 1):.0f} %)",
                  file=sys.stderr, flush=True)

    yield line


def _absolute(text: str) -> Path:
    """A path from the command line, made absolute against the current directory."""
    return Path(os.path.abspath(os.path.expanduser(text)))


def main(argv: list[str]) -> int:
    program = os.environ.get("HLVS_PROG", "python -m simulator")
    parser = argparse.ArgumentParser(
        prog=f"{program} render", description="Render a match replay to a video, offscreen."
    )
    parser.add_argument("replay", type=_absolute, help="replay file of a match (replay.hlvsrec)")
    parser.add_argument("-o", "--output", type=_absolute, default=None,
                        help="video file to write (default: match.mp4); with --camera, the "
                        "folder of the PNG frames (default: frames)")
    parser.add_argument("--camera", metavar="ROBOT", default=None,
                        help="write what this robot's head camera saw (red-1, blue-2...) as PNG "
                        "frames at its own resolution instead of the video")
    parser.add_argument("--ideal", action="store_true",
                        help="with --camera: without the camera model's exposure and noise")
    parser.add_argument("--width", type=int, default=1280, help="pixels (default 1280)")
    parser.add_argument("--height", type=int, default=720, help="pixels (default 720)")
    parser.add_argument("--fps", type=float, default=25.0, help="frames per second (default 25)")
    args = parser.parse_args(argv)
    logging.basicConfig(level=logging.INFO, format="%(levelname)s %(name)s: %(message)s")
    if args.width <= 0 or args.height <= 0 or args.fps <= 0:
        print("error: --width, --height and --fps must be positive", file=sys.stderr)
        return 2
    if not args.replay.is_file():
        print(f"error: {args.replay}: no such replay file", file=sys.stderr)
        return 2
    try:
        backend = choose_offscreen_gl()
    except OffscreenGLError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 3
    logger.info("offscreen OpenGL back end: %s", backend)
    if args.output is None:
        args.output = _absolute("frames" if args.camera else "match.mp4")
    try:
        with _frame_progress(f"render {args.output.name}") as on_frame:
            if args.camera:
                from simulator.camera_frames import render_camera_frames

                files = render_camera_frames(args.replay, args.output, robot=args.camera,
                                             fps=args.fps, ideal=args.ideal, on_frame=on_frame)
                logger.info("wrote %d frames of %s's camera to %s", len(files), args.camera,
                            args.output)
            else:
                render_video(args.replay, args.output, width=args.width, height=args.height,
                             fps=args.fps, on_frame=on_frame)
    except ReplayError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except RenderError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    return 0
