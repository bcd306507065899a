"""``hlvs bench video``: how fast ``hlvs render`` turns a replay into a match video.

It records a replay of the kid field with eight robots standing and the ball rolling across it
(``--sim-seconds``, 25 frames a second), or takes ``--replay PATH`` (e.g. the one
``make scrimmage`` writes), and renders it as ``hlvs render`` does (1280x720 at 25 fps by
default) into a scratch folder. One JSON line::

    {"bench": "video", "frames": 500, "width": 1280, "height": 720, "fps": 25.0,
     "wall_s": ..., "ms_per_frame": ..., "x_real_time": ..., "render_cpu_ms_per_frame": ...,
     "ffmpeg_cpu_ms_per_frame": ..., "gl_renderer": "llvmpipe (LLVM 15.0.6, 256 bits)"}

``x_real_time`` is the video's length over the wall time (a match of 2 x 10 min takes its
length over this to render); the CPU figures are the rendering process's (its OpenGL threads
included) and ffmpeg's, a frame each.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from pathlib import Path

from benchmarks.sim import placements


def record(path: Path, sim_seconds: float, robots: int = 8) -> None:
    """A replay of ``robots`` kid robots standing on the kid field while the ball rolls."""
    from referee.snapshot import PlaceBall
    from simulator.recorder import Recorder
    from simulator.world import World

    world = World.create(field_class="kid", robots=placements(robots, "kid-default"), seed=0)
    world.apply(PlaceBall(position=(-3.0, -2.0, 0.07), velocity=(1.2, 0.8, 0.0)))
    steps = max(1, round(sim_seconds * 1000 / world.step_ms))
    with Recorder(path, world, match_id="bench-video", rate_hz=25.0) as recorder:
        for _ in range(steps):
            world.step()
            recorder.record(world, {"state": "PLAYING", "score": {"red": 0, "blue": 0}})


def _cpu(who: int) -> float:
    usage = resource.getrusage(who)
    return usage.ru_utime + usage.ru_stime


def run(
    *, replay: Path | None, sim_seconds: float, width: int, height: int, fps: float
) -> dict[str, object]:
    from simulator.gl import choose_offscreen_gl

    choose_offscreen_gl()  # before MuJoCo is imported
    from simulator.render import render_video
    from simulator.scene_model import frames_for

    source = str(replay) if replay is not None else f"recorded: 8 robots, {sim_seconds:g} s"
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-video-") as scratch:
        if replay is None:
            replay = Path(scratch) / "replay.hlvsrec"
            record(replay, sim_seconds)
        from simulator.replay import load_replay

        frames = len(list(frames_for(load_replay(replay), fps)))
        renderer: list[str] = []

        def first_frame(done: int, total: int) -> None:
            if not renderer:
                from OpenGL import GL

                name = GL.glGetString(GL.GL_RENDERER)
                renderer.append(name.decode() if isinstance(name, bytes) else str(name))

        own, ffmpeg = _cpu(resource.RUSAGE_SELF), _cpu(resource.RUSAGE_CHILDREN)
        started = time.perf_counter()
        render_video(replay, Path(scratch) / "match.mp4", width=width, height=height, fps=fps,
                     on_frame=first_frame)  # fmt: skip
        wall = time.perf_counter() - started
        own, ffmpeg = _cpu(resource.RUSAGE_SELF) - own, _cpu(resource.RUSAGE_CHILDREN) - ffmpeg
    per_frame = 1000.0 / max(frames, 1)
    return {
        "bench": "video",
        "replay": source,
        "frames": frames,
        "width": width,
        "height": height,
        "fps": fps,
        "wall_s": round(wall, 2),
        "ms_per_frame": round(wall * per_frame, 2),
        "x_real_time": round(frames / fps / wall, 3) if wall > 0 else None,
        "render_cpu_ms_per_frame": round(own * per_frame, 2),
        "ffmpeg_cpu_ms_per_frame": round(ffmpeg * per_frame, 2),
        "gl_renderer": renderer[0] if renderer else None,
    }


def main(argv: list[str]) -> int:
    program = os.environ.get("HLVS_PROG", "python -m benchmarks")
    parser = argparse.ArgumentParser(
        prog=f"{program} bench video",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "--replay",
        type=Path,
        default=None,
        help="a replay to render (default: one recorded here, see --sim-seconds)",
    )
    parser.add_argument(
        "--sim-seconds", type=float, default=20.0, help="length of the recorded replay (default 20)"
    )
    parser.add_argument("--width", type=int, default=1280, help="pixels (default 1280)")
    parser.add_argument("--height", type=int, default=720, help="pixels (default 720)")
    parser.add_argument("--fps", type=float, default=25.0, help="frames a second (default 25)")
    parser.add_argument("--json", action="store_true", help="print only the JSON line")
    args = parser.parse_args(argv)
    if args.sim_seconds <= 0 or args.fps <= 0 or args.width < 16 or args.height < 16:
        parser.error("--sim-seconds and --fps must be positive, --width and --height 16 or more")
    if args.replay is not None and not args.replay.is_file():
        parser.error(f"--replay: {args.replay}: no such replay file")
    from simulator.errors import OffscreenGLError, RenderError, ReplayError

    try:
        result = run(replay=args.replay, sim_seconds=args.sim_seconds, width=args.width,
                     height=args.height, fps=args.fps)  # fmt: skip
    except (RenderError, ReplayError, OffscreenGLError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    if not args.json:
        print(f"{result['frames']} frames of {args.width}x{args.height} in {result['wall_s']} s: "
              f"{result['ms_per_frame']} ms a frame, {result['x_real_time']} x real time",
              file=sys.stderr)  # fmt: skip
    print(json.dumps(result, sort_keys=True))
    return 0


__all__ = ["main", "record", "run"]
