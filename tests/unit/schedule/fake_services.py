"""Services for scheduler tests: a 'match' is a short sleep with a score derived from the names.

``HLVS_FAKE_DRAWN`` (match ids) ends those matches 1-1; ``HLVS_FAKE_DEAD_TEAMS`` (team names)
makes those teams' log deliveries fail as an unreachable target would (the set stays in the log
store). Both are read when the
module is imported (set them before the scheduler's first job, or in a child's environment).

Every step appends a line to ``<output_dir>/services.log`` (``pull|play-start|play-end|deliver
<match id> <time>``) so tests can count what ran and when, across scheduler processes.
"""

from __future__ import annotations

import json
import os
import time
import zlib
from datetime import UTC, datetime

from orchestrator.config.schedule import Schedule
from tournament.logs import TeamLogs
from tournament.services import MatchContext, PlayOutcome

PLAY_SECONDS = float(os.environ.get("HLVS_FAKE_PLAY_S", "0.3"))
DEAD_TEAMS = set(filter(None, os.environ.get("HLVS_FAKE_DEAD_TEAMS", "").split(",")))
DRAWN = set(filter(None, os.environ.get("HLVS_FAKE_DRAWN", "").split(",")))
BROKEN: set[str] = set()  # match ids whose play fails as a killed match process does
STOP_AFTER_PLAY: set[str] = set()  # match ids after whose play the scheduler is stopped


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
        ctx.out_dir.mkdir(parents=True, exist_ok=True)
        (ctx.out_dir / "game_defaults.json").write_text(json.dumps(ctx.schedule.game_defaults))
        until = time.monotonic() + PLAY_SECONDS
        while time.monotonic() < until:
            if ctx.abort() is not None:
                _log(self.schedule, "play-stopped", ctx.match_id)
                return PlayOutcome(status="infrastructure", score_red=None, score_blue=None,
                                   winner=None, cause="stopped (SIGTERM)")
            time.sleep(0.02)
        red, blue = goals(ctx.red.name), goals(ctx.blue.name)
        if ctx.planned.match.id in BROKEN:
            return PlayOutcome(status="infrastructure", score_red=None, score_blue=None,
                               winner=None, cause="report.json was not written")
        if ctx.planned.match.id in DRAWN:
            red = blue = 1
        _log(self.schedule, "play-end", ctx.match_id)
        if ctx.planned.match.id in STOP_AFTER_PLAY:  # SIGTERM as the match ends
            from tournament.jobs import STOPPING

            STOPPING.set()
        winner = "red" if red > blue else "blue" if blue > red else "draw"
        return PlayOutcome(status="success", score_red=red, score_blue=blue, winner=winner)

    def shootout(self, ctx: MatchContext) -> PlayOutcome:
        _log(self.schedule, "shootout", ctx.match_id)
        red, blue = (3, 2) if goals(ctx.red.name) >= goals(ctx.blue.name) else (2, 3)
        winner = "red" if red > blue else "blue"
        return PlayOutcome(status="success", score_red=red, score_blue=blue, winner=winner,
                           shootout={"red": red, "blue": blue})

    def deliver(self, ctx: MatchContext) -> list[TeamLogs]:
        _log(self.schedule, "deliver", ctx.match_id)
        for team in (ctx.red.name, ctx.blue.name):
            if team in DEAD_TEAMS:
                self._leave_in_store(ctx, team)
        return [self._one(ctx.red.name), self._one(ctx.blue.name)]

    def _leave_in_store(self, ctx: MatchContext, team: str) -> None:
        """A set that failed stays in the log store, as the real services leave it."""
        from orchestrator.delivery.store import create_set

        source = ctx.out_dir / f"{team}.log"
        source.parent.mkdir(parents=True, exist_ok=True)
        source.write_text("log\n")
        create_set(self.schedule.log_store, match_id=ctx.league_id, team=team, kind="team",
                   credentials=None, sources=[(source, "robot.log")], move=False)

    def redeliver(self, ctx: MatchContext) -> list[TeamLogs]:
        _log(self.schedule, "redeliver", ctx.match_id)
        return [self._one(name) for name in (ctx.red.name, ctx.blue.name)
                if name in DEAD_TEAMS]

    def _one(self, team: str) -> TeamLogs:
        if team in DEAD_TEAMS:
            return TeamLogs(team=team, state="failed", target="sftp://127.0.0.1:9",
                            cause="unreachable: connection refused")
        return TeamLogs(team=team, state="delivered", target="s3://logs")


class MatchFolderServices(FakeServices):
    """Plays as ``hlvs match`` leaves a match: report.json, results.json (built by the
    orchestrator's own :func:`orchestrator.match.results.build_results`) and the public
    sim_result.json, read back by :func:`tournament.services.read_outcome`. A match in
    ``DRAWN`` ends 0-0 after extra time and the referee's shoot-out 3-2 (the GameController's
    score, 3-2, counts the shoot-out's goals)."""

    def play(self, ctx: MatchContext) -> PlayOutcome:
        from contracts import MatchReport, files
        from contracts.sim_result import SimResult
        from orchestrator.match.results import build_results
        from tests.unit.match.test_match_results_build import LIMITS
        from tournament.services import read_outcome

        _log(self.schedule, "play-start", ctx.match_id)
        out = ctx.out_dir / "match"
        (out / "public").mkdir(parents=True, exist_ok=True)
        if ctx.match_id in DRAWN:
            sim = SimResult(match_id=ctx.match_id, seed=1, state="FINISHED",
                            score={"red": 3, "blue": 2}, winner="red",
                            shootout={"red": {"kicks": 5, "scored": 3},
                                      "blue": {"kicks": 5, "scored": 2}}, coin_toss=False)
        else:
            red, blue = goals(ctx.red.name), goals(ctx.blue.name) + 4
            sim = SimResult(match_id=ctx.match_id, seed=1, state="FINISHED",
                            score={"red": red, "blue": blue}, winner="blue")
        sim.write(out / "public" / files.SIM_RESULT)
        build_results(match_id=ctx.match_id, seed=1, sim_result=sim, robots=[], forfeit=None,
                      limits=LIMITS, versions={}, timings_s={}, failure=None,
                      ).write(out / files.RESULTS)
        MatchReport.of(None).write(out / files.REPORT)
        _log(self.schedule, "play-end", ctx.match_id)
        return read_outcome(out)
