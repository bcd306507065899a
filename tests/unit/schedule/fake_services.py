"""Services for scheduler tests: a 'match' is a short sleep with a score derived from the names.

Every step appends a line to ``<output_dir>/services.log`` (``pull|play-start|play-end|deliver
<match id> <time>``) so tests can count what ran and when, across scheduler processes.
"""

from __future__ import annotations

import os
import time
import zlib
from datetime import UTC, datetime

from orchestrator.config.schedule import Schedule
from tournament.services import MatchContext, PlayOutcome

PLAY_SECONDS = float(os.environ.get("HLVS_FAKE_PLAY_S", "0.3"))


def _log(schedule: Schedule, what: str, match_id: str) -> None:
    schedule.output_dir.mkdir(parents=True, exist_ok=True)
    with open(schedule.output_dir / "services.log", "a", encoding="utf-8") as fh:
        fh.write(f"{what} {match_id} {datetime.now(UTC).isoformat()}\n")
        fh.flush()
        os.fsync(fh.fileno())


def goals(name: str) -> int:
    return zlib.crc32(name.encode()) % 4


class FakeServices:
    def __init__(self, schedule: Schedule) -> None:
        self.schedule = schedule

    def pull(self, ctx: MatchContext) -> str:
        _log(self.schedule, "pull", ctx.match_id)
        return "2 images"

    def play(self, ctx: MatchContext) -> PlayOutcome:
        _log(self.schedule, "play-start", ctx.match_id)
        time.sleep(PLAY_SECONDS)
        red, blue = goals(ctx.red.name), goals(ctx.blue.name)
        if ctx.planned.match.kind == "knockout" and red == blue:
            red += 1  # decided by the shoot-out in a real knockout match
        _log(self.schedule, "play-end", ctx.match_id)
        winner = "red" if red > blue else "blue" if blue > red else "draw"
        return PlayOutcome(status="success", score_red=red, score_blue=blue, winner=winner)

    def deliver(self, ctx: MatchContext) -> str:
        _log(self.schedule, "deliver", ctx.match_id)
        return "2 log sets delivered"
