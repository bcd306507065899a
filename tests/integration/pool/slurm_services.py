"""Scheduler services for the Slurm restart test: matches really played through the Slurm pool
(:class:`MatchServices`), pulls and deliveries only recorded (no registry, no log targets).

Every step appends ``pull|play-start|play-end|deliver <match id>`` to
``<output_dir>/services.log``, across scheduler processes.
"""

from __future__ import annotations

import os

from tournament.logs import TeamLogs
from tournament.services import MatchContext, MatchServices, PlayOutcome


class SlurmTestServices(MatchServices):
    def _log(self, what: str, match_id: str) -> None:
        self.schedule.output_dir.mkdir(parents=True, exist_ok=True)
        with open(self.schedule.output_dir / "services.log", "a", encoding="utf-8") as fh:
            fh.write(f"{what} {match_id}\n")
            fh.flush()
            os.fsync(fh.fileno())

    def pull(self, ctx: MatchContext) -> str:
        self._log("pull", ctx.match_id)
        return "local images"

    def play(self, ctx: MatchContext) -> PlayOutcome:
        self._log("play-start", ctx.match_id)
        outcome = super().play(ctx)
        self._log("play-end", ctx.match_id)
        return outcome

    def deliver(self, ctx: MatchContext) -> list[TeamLogs]:
        self._log("deliver", ctx.match_id)
        return [TeamLogs(team=team.name, state="delivered", target="(recorded only)")
                for team in (ctx.red, ctx.blue)]
