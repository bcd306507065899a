"""``hlvs bench viewer``: open a full 2 x 10 min 4 v 4 replay in headless Chromium and play it.

Writes the replay first (unless ``--replay`` gives one): the real world model with eight
kid-size robots, posed kinematically (no physics, so that 20 minutes take seconds): each robot
walks a Lissajous path with swinging joints, the ball rolls between them, two halves of
600 s, goals and state changes as referee events. Then starts ``hlvs view`` on loopback, opens
the page in Debian's Chromium (WebGL through SwiftShader, as in the browser tests) and measures:

- ``open_s``: navigation start to the first frame drawn with the replay's poses;
- ``seek_s``: a seek to 15:00 until that frame is drawn;
- ``fps``: frames drawn per second while playing at 1x (``play_s`` seconds), with the render
  scale the viewer chose (it halves the resolution while playing when frames are slow);
- ``browser_cpu_ms_per_frame``: CPU time of the browser's processes (all of them: WebGL runs in
  software) per frame drawn while playing; it depends much less on the machine's load than
  ``fps``, so it compares versions of the viewer measured at different times;
- ``draw_calls`` and ``triangles`` of one frame.

The machine's load average is printed too: software WebGL shares the CPU with everything else.

Prints one JSON line.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, TypedDict

from orchestrator.paths import user_path

HALF_S = 600
RATE_HZ = 25.0
CHROMIUM = "/usr/bin/chromium"
# WebGL in software (SwiftShader); the GPU work in the browser process without compositing:
# measured about 3x more frames per second on a loaded 2-core machine than a GPU process.
LAUNCH_ARGS = [
    "--use-angle=swiftshader", "--enable-unsafe-swiftshader", "--no-sandbox",
    "--in-process-gpu", "--disable-gpu-compositing",
]


class ReplayWritten(TypedDict):
    write_s: float  # wall time to write the replay
    bodies: int  # bodies per frame


def write_replay(path: Path, *, half_s: int = HALF_S, seed: int = 7) -> ReplayWritten:
    """A 4 v 4 replay of two halves of ``half_s`` seconds (see the module docstring)."""
    import mujoco
    import numpy as np

    from contracts.ids import RobotId, TeamColor
    from simulator.recorder import Recorder
    from simulator.world import RobotPlacement, World

    placements = [
        RobotPlacement(id=RobotId(team, n), model="kid-default", x_m=sign * (0.8 + 0.8 * n),
                       y_m=-1.5 + (n - 1), yaw_rad=0.0 if sign < 0 else math.pi)
        for team, sign in ((TeamColor.RED, -1.0), (TeamColor.BLUE, 1.0)) for n in range(1, 5)
    ]  # fmt: skip
    world = World.create(field_class="kid", robots=placements, seed=seed)
    model, data = world.model, world.data
    rng = np.random.default_rng(seed)
    phases = rng.uniform(0, 2 * math.pi, size=(len(placements), 4))
    ball_adr = int(model.joint("ball/root").qposadr[0])
    started = time.monotonic()
    score = {"red": 0, "blue": 0}
    step_ms = int(1000 / RATE_HZ)
    end_ms = 2 * half_s * 1000
    with Recorder(path, world, match_id="bench-viewer-4v4", rate_hz=RATE_HZ) as recorder:
        for t_ms in range(step_ms, end_ms + 1, step_ms):
            t = t_ms / 1000.0
            for k, robot in enumerate(world.index.robots):
                a, b, c, d = phases[k]
                home = placements[k]
                x = home.x_m + 1.2 * math.sin(0.11 * t + a)
                y = home.y_m + 0.8 * math.sin(0.07 * t + b)
                yaw = home.yaw_rad + 0.6 * math.sin(0.05 * t + c)
                q = robot.root_qpos
                data.qpos[q : q + 3] = (x, y, 0.38)
                data.qpos[q + 3 : q + 7] = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
                swing = np.arange(robot.motor_qpos.size)
                data.qpos[robot.motor_qpos] = 0.3 * np.sin(2.0 * t + d + swing)
            ball = (3.5 * math.sin(0.2 * t), 2.0 * math.sin(0.13 * t), 0.07)
            data.qpos[ball_adr : ball_adr + 3] = ball
            mujoco.mj_kinematics(model, data)
            world.sim_time_ms = t_ms
            half = 1 if t_ms <= half_s * 1000 else 2
            if t_ms % 150_000 == 0:
                team = "red" if (t_ms // 150_000) % 2 else "blue"
                score[team] += 1
                recorder.event({"type": "goal", "team": team, "player": 2, "sim_time_ms": t_ms,
                                "reason": "", "placement": None, "details": {}})
            if t_ms == half_s * 1000:
                recorder.event({"type": "state", "team": None, "player": None,
                                "reason": "FINISHED", "sim_time_ms": t_ms, "placement": None,
                                "details": {}})
            secs = half_s - (t_ms / 1000 - (half - 1) * half_s)
            recorder.record(world, {"state": "PLAYING", "half": half, "score": dict(score),
                                    "secs_remaining": int(secs)})
        recorder.close(world)
    return {"write_s": round(time.monotonic() - started, 2), "bodies": model.nbody}


def _cpu_s(root_pid: int) -> float:
    """CPU seconds (user + system) of ``root_pid`` and its descendants (``/proc``)."""
    parents: dict[int, int] = {}
    ticks: dict[int, int] = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            fields = Path(f"/proc/{entry}/stat").read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        parents[int(entry)] = int(fields[1])
        ticks[int(entry)] = int(fields[11]) + int(fields[12])
    tree, grew = {root_pid}, True
    while grew:
        grew = False
        for pid, parent in parents.items():
            if parent in tree and pid not in tree:
                tree.add(pid)
                grew = True
    return sum(ticks.get(pid, 0) for pid in tree) / os.sysconf("SC_CLK_TCK")


def _browser_pid(marker: str) -> int | None:
    """The browser's main process: the one whose command line has ``marker`` (an unknown
    switch Chromium ignores) and no ``--type=`` (its children have one)."""
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                command = Path(f"/proc/{entry}/cmdline").read_bytes().split(b"\0")
            except OSError:
                continue
            if marker.encode() in command and not any(c.startswith(b"--type=") for c in command):
                return int(entry)
    return None


def measure(url: str, *, play_s: float, width: int, height: int, extra_args: list[str]
            ) -> dict[str, Any]:
    from playwright.sync_api import sync_playwright

    marker = f"--hlvs-bench-viewer={os.getpid()}"
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=CHROMIUM, headless=True, args=LAUNCH_ARGS + extra_args + [marker]
        )
        browser_pid = _browser_pid(marker)
        page = browser.new_page(viewport={"width": width, "height": height})
        started = time.monotonic()
        page.goto(url)
        page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=60_000,
                               polling=10)
        open_s = time.monotonic() - started
        started = time.monotonic()
        duration = page.evaluate("window.hlvsViewer.meta.duration_ms")
        page.evaluate(f"window.hlvsViewer.seek({int(duration * 0.75)})")
        page.wait_for_function("window.hlvsViewer.ready", timeout=60_000, polling=10)
        seek_s = time.monotonic() - started
        probe = "[window.hlvsViewer.frames, performance.now(), window.hlvsViewer.time]"
        page.locator("[data-testid=play]").click()
        page.wait_for_timeout(500)  # the render scale settles
        cpu_before = _cpu_s(browser_pid) if browser_pid else None
        before = page.evaluate(probe)
        page.wait_for_timeout(play_s * 1000)
        after = page.evaluate(probe)
        cpu_after = _cpu_s(browser_pid) if browser_pid else None
        scale = page.evaluate("window.hlvsViewer.scale")
        drawn = page.evaluate("window.hlvsViewer.view.renderer.info.render")
        browser.close()
    wall_s = (after[1] - before[1]) / 1000.0
    frames = max(1, after[0] - before[0])
    return {
        "browser_cpu_ms_per_frame": None if cpu_before is None or cpu_after is None
        else round(1000 * (cpu_after - cpu_before) / frames, 1),
        "draw_calls": drawn["calls"],
        "triangles": drawn["triangles"],
        "open_s": round(open_s, 3),
        "seek_s": round(seek_s, 3),
        "fps": round((after[0] - before[0]) / wall_s, 1),
        "played_sim_s": round((after[2] - before[2]) / 1000.0, 2),
        "play_wall_s": round(wall_s, 2),
        "render_scale_playing": scale,
    }


def main(argv: list[str]) -> int:
    prog = f"{os.environ.get('HLVS_PROG', 'python -m benchmarks.viewer')} bench viewer"
    parser = argparse.ArgumentParser(prog=prog, description=__doc__.splitlines()[0])
    parser.add_argument("--replay", type=user_path, help="an existing replay (default: write one)")
    parser.add_argument("--half-s", type=int, default=HALF_S, help="seconds per half (600)")
    parser.add_argument("--play-s", type=float, default=8.0, help="seconds of playback measured")
    parser.add_argument("--width", type=int, default=1300, help="browser window width")
    parser.add_argument("--height", type=int, default=900, help="browser window height")
    parser.add_argument(
        "--chromium-arg", action="append", default=[], metavar="ARG",
        help="an extra Chromium command-line switch (repeatable), e.g. --in-process-gpu",
    )
    parser.add_argument("--json", action="store_true", help="accepted: the output is JSON")
    args = parser.parse_args(argv)
    if not Path(CHROMIUM).exists():
        print(f"bench viewer: needs {CHROMIUM} (apt-get install chromium)", file=sys.stderr)
        return 3
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-viewer-") as tmp:
        result: dict[str, Any] = {"benchmark": "viewer"}
        replay = args.replay
        if replay is None:
            replay = Path(tmp) / "replay.hlvsrec"
            result.update(write_replay(replay, half_s=args.half_s))
        from simulator.replay import ReplayFile

        with ReplayFile(replay) as opened:
            result.update(replay_mb=round(replay.stat().st_size / 1e6, 1),
                          duration_s=opened.duration_ms / 1000, frames=opened.frame_count,
                          robots=len(opened.header.robots), bodies=opened.nbody,
                          chunks=len(opened.chunks))  # fmt: skip
        hlvs = shutil.which("hlvs", path=str(Path(sys.executable).parent)) or "hlvs"
        proc = subprocess.Popen([hlvs, "view", str(replay)], stdout=subprocess.PIPE, text=True)
        try:
            assert proc.stdout is not None
            url = proc.stdout.readline().strip()
            if not url.startswith("http"):
                print(f"bench viewer: hlvs view printed {url!r}", file=sys.stderr)
                return 1
            result.update(measure(url, play_s=args.play_s, width=args.width, height=args.height,
                                  extra_args=args.chromium_arg))
            result["chromium_args"] = LAUNCH_ARGS + args.chromium_arg
        finally:
            proc.terminate()
            proc.wait(timeout=10)
        result.update(load_avg_1m=os.getloadavg()[0], cpus=os.cpu_count())
        result.update(open_under_3_s=result["open_s"] < 3.0, fps_at_least_30=result["fps"] >= 30)
    print(json.dumps(result, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
