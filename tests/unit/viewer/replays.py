"""A short recorded match for the viewer tests: eight robots, real physics, a goal event."""

from __future__ import annotations

import json
from pathlib import Path

from referee.snapshot import PlaceBall
from simulator.recorder import Recorder
from simulator.world import World
from tests.unit.world.conftest import eight_robots

GOAL_MS = 2600


def record_match(folder: Path, *, seconds: float = 3.0,
                 events: tuple[dict[str, object], ...] = ()) -> Path:
    """``folder/public/replay.hlvsrec`` (and ``api_stats.jsonl`` beside it): PLAYING, first half,
    red scores at ``GOAL_MS``; the ball rolls towards the blue goal. ``events``: more referee
    events, each recorded at its ``sim_time_ms``."""
    public = folder / "public"
    public.mkdir(parents=True, exist_ok=True)
    path = public / "replay.hlvsrec"
    world = World.create(field_class="kid", robots=eight_robots(), seed=11)
    world.apply(PlaceBall(position=(0.5, 0.3, 0.07), velocity=(1.5, 0.4, 0.0)))
    score = {"red": 0, "blue": 0}
    with Recorder(path, world, match_id="viewer-test", chunk_frames=25) as recorder:
        for _ in range(int(seconds * 125)):
            world.step()
            if world.sim_time_ms == GOAL_MS:
                score = {"red": 1, "blue": 0}
                recorder.event({"type": "goal", "team": "red", "player": 2,
                                "sim_time_ms": world.sim_time_ms, "reason": ""})  # fmt: skip
            for event in events:
                if event["sim_time_ms"] == world.sim_time_ms:
                    recorder.event(dict(event))
            recorder.record(world, {"state": "PLAYING", "half": 1, "score": dict(score),
                                    "secs_remaining": 600 - world.sim_time_ms // 1000})  # fmt: skip
        recorder.close(world)
    samples = [
        {"real_time_s": float(k), "sim_time_ms": 1000 * k, "real_time_factor": 1.0 + 0.1 * k,
         "robots": {"red-1": {"connected": True, "bytes_in": 1000 * k, "bytes_out": 50000 * k,
                              "messages_in": 125 * k, "messages_out": 125 * k,
                              "round_trip_ms": 2.0 + k}}}
        for k in range(int(seconds) + 1)
    ]  # fmt: skip
    (public / "api_stats.jsonl").write_text(
        "".join(json.dumps(s) + "\n" for s in samples), encoding="utf-8"
    )
    return path
