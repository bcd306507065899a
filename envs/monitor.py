"""Monitoring of an environment served over HTTP: episode statistics and an optional video.

Files in the instance's monitor folder: ``episodes.jsonl`` (one line per finished episode:
``episode``, ``steps``, ``reward``, ``sim_time_s``, ``terminated``, ``truncated`` and the last
info's numbers such as ``kick_distance_m``), ``stats.json`` (written at close: episodes, steps,
mean reward, the best kick) and ``video.mp4`` when asked for (the field's overview camera at
25 frames per simulated second, 480 x 270, rendered from the in-process world; ffmpeg needed).
"""

from __future__ import annotations

import json
import logging
import shutil
import subprocess
from pathlib import Path
from typing import Any, TypedDict

log = logging.getLogger(__name__)

VIDEO_SIZE = (480, 270)
VIDEO_PERIOD_MS = 40


class Monitor:
    def __init__(self, folder: Path, *, video: bool, world_of: Any) -> None:
        self.folder = folder
        folder.mkdir(parents=True, exist_ok=True)
        self.episodes = 0
        self.steps = 0
        self._episode_reward = 0.0
        self._episode_steps = 0
        self._rewards: list[float] = []
        self._best_kick = 0.0
        self._world_of = world_of  # () -> the in-process world or None
        self.video_error: str | None = None
        self._video: Any = None
        self._next_frame_ms = 0
        self._episodes_file = (folder / "episodes.jsonl").open("a", encoding="utf-8")
        if video:
            self._start_video()

    def _start_video(self) -> None:
        ffmpeg = shutil.which("ffmpeg")
        if ffmpeg is None:
            self.video_error = "ffmpeg not found on PATH"
            return
        w, h = VIDEO_SIZE
        command = [
            ffmpeg, "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
            "-s", f"{w}x{h}", "-r", str(1000 // VIDEO_PERIOD_MS), "-i", "-", "-c:v", "libx264",
            "-preset", "veryfast", "-pix_fmt", "yuv420p", str(self.folder / "video.mp4"),
        ]  # fmt: skip
        self._video = _Video(command)

    def on_reset(self, sim_time_ms: int) -> None:
        self._episode_reward = 0.0
        self._episode_steps = 0
        self._next_frame_ms = sim_time_ms
        self._frame(sim_time_ms)

    def on_step(
        self, reward: float, terminated: bool, truncated: bool, info: dict[str, Any]
    ) -> None:
        self.steps += 1
        self._episode_steps += 1
        self._episode_reward += reward
        self._frame(int(info.get("sim_time_ms", 0)))
        if terminated or truncated:
            self.episodes += 1
            self._rewards.append(self._episode_reward)
            numbers = {k: v for k, v in info.items() if isinstance(v, int | float | bool)}
            self._best_kick = max(self._best_kick, float(numbers.get("kick_distance_m", 0.0)))
            line = {
                "episode": self.episodes, "steps": self._episode_steps,
                "reward": round(self._episode_reward, 6),
                "sim_time_s": numbers.get("sim_time_ms", 0) / 1000.0,
                "terminated": terminated, "truncated": truncated, **numbers,
            }  # fmt: skip
            self._episodes_file.write(json.dumps(line) + "\n")
            self._episodes_file.flush()

    def _frame(self, sim_time_ms: int) -> None:
        if self._video is None or sim_time_ms < self._next_frame_ms:
            return
        self._next_frame_ms = sim_time_ms + VIDEO_PERIOD_MS
        world = self._world_of()
        if world is None:
            return
        try:
            self._video.add(world)
        except Exception as exc:  # noqa: BLE001 (a video problem never fails a step)
            self.video_error = f"{type(exc).__name__}: {exc}"
            log.warning("monitor video stopped: %s", self.video_error)
            self._video.close()
            self._video = None

    def close(self) -> MonitorStats:
        if self._video is not None:
            error = self._video.close()
            self.video_error = self.video_error or error
            self._video = None
        self._episodes_file.close()
        stats: MonitorStats = {
            "episodes": self.episodes,
            "steps": self.steps,
            "mean_episode_reward": round(sum(self._rewards) / len(self._rewards), 6)
            if self._rewards
            else None,
            "best_kick_distance_m": round(self._best_kick, 3),
            "video": (self.folder / "video.mp4").is_file(),
            "video_error": self.video_error,
        }
        (self.folder / "stats.json").write_text(json.dumps(stats, indent=2), encoding="utf-8")
        return stats


class MonitorStats(TypedDict):
    """What a monitor reports when it closes (also its ``stats.json``)."""

    episodes: int
    steps: int
    mean_episode_reward: float | None
    best_kick_distance_m: float
    video: bool
    video_error: str | None


class _Video:
    """Overview-camera frames of a world piped into ffmpeg."""

    def __init__(self, command: list[str]) -> None:
        self._proc = subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE)
        self._renderer: Any = None
        self._model: Any = None

    def add(self, world: Any) -> None:
        import mujoco

        if self._renderer is None or self._model is not world.model:
            if self._renderer is not None:
                self._renderer.close()
            w, h = VIDEO_SIZE
            self._renderer = mujoco.Renderer(world.model, height=h, width=w)
            self._renderer.scene.flags[mujoco.mjtRndFlag.mjRND_SHADOW] = False
            self._model = world.model
        self._renderer.update_scene(world.data, camera="overview")
        assert self._proc.stdin is not None
        self._proc.stdin.write(self._renderer.render().tobytes())

    def close(self) -> str | None:
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        assert self._proc.stdin is not None
        try:
            self._proc.stdin.close()
        except BrokenPipeError:
            pass
        stderr = self._proc.stderr.read().decode(errors="replace") if self._proc.stderr else ""
        code = self._proc.wait()
        return None if code == 0 else f"ffmpeg exited {code}: {stderr.strip()}"
