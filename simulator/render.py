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
import queue
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

from simulator.errors import OffscreenGLError, RenderError, ReplayError
from simulator.gl import choose_offscreen_gl
from simulator.scene_model import Placer, frames_for, scene_model

if TYPE_CHECKING:  # numpy, MuJoCo and the replay reader are imported after the arguments
    from contracts import GameStateRecord
    from simulator.replay import Replay

logger = logging.getLogger(__name__)


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


VIDEO_SHADOWS_ENV = "HLVS_VIDEO_SHADOWS"


def video_shadows() -> bool:
    """Whether the match video has the key light's shadows (with the renderer's context
    current): ``HLVS_VIDEO_SHADOWS`` ``on`` or ``off``, else on a GPU only. On a CPU renderer a
    1280x720 frame with shadows took 290 ms where it took 135 ms without (osmesa, a kid
    scrimmage), which would double a match video's wait."""
    from simulator.world.camera import software_gl

    wanted = os.environ.get(VIDEO_SHADOWS_ENV, "").strip().lower()
    if wanted in ("on", "1", "true"):
        return True
    if wanted in ("off", "0", "false"):
        return False
    return not software_gl()


def video_surfaces(model: Any) -> None:
    """Set a replay's scene ``model`` to draw each face of a box as one quad (MuJoCo's default
    is 4 x 4: the 324 boxes of a kid scrimmage's scene, most of them the nets' cords and the
    lines, were 62,000 triangles a frame) and the turf in 1 m cells
    (:func:`~simulator.world.camera_scene.coarse_turf`; 8,800 quads at its 0.1 m). The look's
    lights are directional, so a flat face is lit the same all over but for the weak specular
    glint, worked out at the corners; the frames differ from the model's own in the odd pixel
    of a cord thinner than a pixel (``tests/unit/replay/test_video_frames.py``). On a CPU
    renderer the video's process took about a third less CPU a frame (README, "Match video")."""
    from simulator.world.camera_scene import coarse_turf

    model.vis.quality.numquads = 1
    coarse_turf(model)


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
    from simulator.world.camera import reads_frames

    output = Path(output)
    ffmpeg = shutil.which("ffmpeg")
    if ffmpeg is None:
        raise RenderError(output=str(output), reason="ffmpeg not found on PATH")
    replay = load_replay(replay_path)
    scene = scene_for(replay.header, str(replay_path))
    model = scene_model(scene)
    if model.nbody != len(replay.header.body_names):
        raise ReplayError(
            path=str(replay_path),
            reason=f"{len(replay.header.body_names)} bodies recorded, the scene has {model.nbody}",
        )
    video_surfaces(model)
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    place = Placer(model, data)
    indices = list(frames_for(replay, fps))
    subtitles = _subtitles(replay, indices, fps)
    srt = output.with_name(output.name + ".srt")
    if subtitles:
        srt.write_text(subtitles, encoding="utf-8")
    renderer = mujoco.Renderer(model, height=height, width=width)
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = video_shadows()
    renderer.scene.flags[mujoco.mjtRndFlag.mjRND_REFLECTION] = False
    option = mujoco.MjvOption()
    option.geomgroup[4] = 0
    # the render buffer's own R,G,B,A rows, bottom up, as OpenGL reads them fastest (ffmpeg
    # drops the alpha and turns the rows); R,G,B top down where they cannot be read so
    read = reads_frames(renderer, "RGBA")
    # one frame drawn while ffmpeg is given the one before and the one before that waits
    frames = [np.empty((height, width, 4), dtype=np.uint8) for _ in range(_FrameFeed.BUFFERS)]
    command = _ffmpeg_command(
        ffmpeg, (width, height), fps, rgba=read is not None, subtitles=srt if subtitles else None,
        output=output,
    )  # fmt: skip
    proc = subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
    assert proc.stdin is not None
    count = 0
    try:
        with _FrameFeed(proc.stdin) as feed:
            for i in indices:
                place(replay.frames[i].poses.astype(np.float64))
                renderer.update_scene(data, camera="overview", scene_option=option)
                if read:
                    chunk: bytes | memoryview = read(frames[count % len(frames)]).data
                else:
                    chunk = renderer.render().tobytes()
                if not feed.put(chunk):
                    break  # ffmpeg has gone: its exit code and message say why
                count += 1
                if on_frame is not None:
                    on_frame(count, len(indices))
    finally:
        renderer.close()
    stderr = proc.stderr.read().decode(errors="replace") if proc.stderr else ""
    code = proc.wait()
    srt.unlink(missing_ok=True)
    if code != 0:
        raise RenderError(output=str(output), reason=f"ffmpeg exited {code}: {stderr.strip()}")
    logger.info("rendered %d frames of %s to %s", count, replay_path, output)
    return output


def _ffmpeg_command(
    ffmpeg: str, size: tuple[int, int], fps: float, *, rgba: bool, subtitles: Path | None,
    output: Path,
) -> list[str]:  # fmt: skip
    """ffmpeg reading raw frames of ``size`` from its standard input (R,G,B,A rows bottom up
    when ``rgba``, else R,G,B rows top down) into an H.264 MP4 at ``output``, with the
    ``subtitles`` file as its text track."""
    command = [
        ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo",
        "-pix_fmt", "rgba" if rgba else "rgb24", "-s", f"{size[0]}x{size[1]}", "-r", f"{fps:g}",
        "-i", "-",
    ]  # fmt: skip
    if subtitles is not None:
        command += ["-i", str(subtitles), "-map", "0:v", "-map", "1:s", "-c:s", "mov_text"]
    if rgba:
        command += ["-vf", "vflip"]  # the rows turned; the alpha goes with the pixel format
    return [*command, "-c:v", "libx264", "-preset", "veryfast", "-pix_fmt", "yuv420p", str(output)]


class _FrameFeed:
    """Frames written to ffmpeg's standard input by a thread of their own, so that the next frame
    is drawn while ffmpeg takes one (a 1280x720 frame is 3.7 MB; a pipe holds 64 kB, and a write
    from the drawing thread waited for ffmpeg to read all of it). At most one frame waits in
    line beside the one being written: the drawing thread keeps :data:`BUFFERS` frame buffers
    and draws into the one neither holds. Closing it ends ffmpeg's input."""

    BUFFERS = 3

    def __init__(self, stdin: IO[bytes]) -> None:
        self._stdin = stdin
        self._line: queue.Queue[bytes | memoryview | None] = queue.Queue(maxsize=1)
        self._thread = threading.Thread(target=self._write, name="video-feed", daemon=True)
        self._thread.start()

    def _write(self) -> None:
        try:
            while (chunk := self._line.get()) is not None:
                self._stdin.write(chunk)
            self._stdin.close()
        except (BrokenPipeError, ValueError):
            pass  # ffmpeg ended early; its exit code and message say why

    def put(self, chunk: bytes | memoryview) -> bool:
        """Hand one frame on (waits while one is in line); False when ffmpeg has gone."""
        return self._hand(chunk)

    def _hand(self, item: bytes | memoryview | None) -> bool:
        while self._thread.is_alive():
            try:
                self._line.put(item, timeout=0.5)
                return True
            except queue.Full:
                continue
        return False

    def __enter__(self) -> _FrameFeed:
        return self

    def __exit__(self, *exc: object) -> None:
        self._hand(None)  # the end of the input
        self._thread.join()
        if not self._stdin.closed:
            try:
                self._stdin.close()
            except BrokenPipeError:
                pass


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
    logging.getLogger("OpenGL").setLevel(logging.WARNING)  # its INFO lines are noise here
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
