"""Building ``results.json`` and ``report.json`` (:mod:`contracts.match_results`) from what the
match recorded: :class:`RobotRecord` per robot (filled in as the match runs), the simulator's
:class:`~contracts.sim_result.SimResult`, the forfeit and the failure.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path

from contracts import (
    MIN_PLAYING_S,
    AdmissionRecord,
    Color,
    Failure,
    FailureClass,
    Forfeit,
    MatchLimits,
    MatchReport,
    MatchResults,
    RobotApiStats,
    RobotResult,
    SimResult,
    TimingSpec,
    files,
    played_enough,
    timing_problem,
)

COLORS: tuple[Color, Color] = ("red", "blue")


@dataclass(slots=True, kw_only=True)
class RobotRecord:
    """One robot during the match: who it is, and its entry of ``results.json`` as recorded so
    far (:class:`contracts.RobotResult`, replaced as the match runs: its image's digest, its
    container and limits, its exit, its peaks, its traffic, its log folder)."""

    key: str
    color: str
    number: int
    entry: RobotResult

    def result(self, api: RobotApiStats | None, *, spoofing_attempts: int = 0) -> RobotResult:
        """The robot's entry of ``results.json``, with what the simulator saw of it."""
        return replace(self.entry, cpu_peak_percent=round(self.entry.cpu_peak_percent, 1),
                       limits=dict(self.entry.limits), api=api,
                       spoofing_attempts=spoofing_attempts)


def build_results(
    *,
    match_id: str,
    seed: int,
    sim_result: SimResult | None,
    robots: list[RobotRecord],
    forfeit: Forfeit | None,
    limits: MatchLimits,
    versions: dict[str, str],
    timings_s: dict[str, float],
    failure: Failure | None,
    bringup_s: float | None = None,
    admission: AdmissionRecord | None = None,
) -> MatchResults:
    sim = sim_result
    api_stats: dict[str, RobotApiStats] = sim.robots if sim is not None else {}
    score = sim.score if sim is not None else None
    winner: str | None = sim.winner if sim is not None else None
    shootout = shootout_goals(sim)
    if score is not None and shootout is not None:  # the GameController's score counts them
        score = {color: goals - shootout.get(color, 0) for color, goals in score.items()}
    if forfeit is not None:
        score, winner, shootout = forfeit.score, forfeit.winner, None
    spoofing = sim.spoofing if sim is not None else None
    spoofed = spoofing.per_sender() if spoofing is not None else {}
    return MatchResults(
        match_id=match_id,
        seed=seed,
        warnings=tuple(team_warnings(robots, api_stats)) if sim is not None else (),
        status="failed" if failure else "success",
        failure=failure,
        forfeit=forfeit,
        final_state=sim.state if sim is not None else None,
        score=score,
        winner=winner,
        shootout=shootout,
        events_summary=sim.events_summary if sim is not None else {},
        play=sim.play if sim is not None else None,
        sim_time_ms=sim.sim_time_ms if sim is not None else None,
        real_time_factor=sim.real_time_factor if sim is not None else None,
        robots={r.key: r.result(api_stats.get(r.key), spoofing_attempts=spoofed.get(r.key, 0))
                for r in robots},
        spoofing=spoofing,
        limits=limits,
        versions={**versions, "simulator": sim.versions if sim is not None else None},
        timings_s=timings_s,
        bringup_s=bringup_s,
        admission=admission,
    )


def shootout_goals(sim: SimResult | None) -> dict[str, int] | None:
    """Goals of each colour in the referee's penalty shoot-out (None when there was none)."""
    if sim is None or sim.shootout is None:
        return None
    return {color: int(kicks.get("scored", 0)) for color, kicks in sim.shootout.items()}


def play_failure(sim: SimResult | None, robots: list[RobotRecord],
                 timing: TimingSpec | None) -> Failure | None:
    """A game that reached FINISHED without football (:func:`contracts.timing.played_enough`),
    classified by its cause: the league's timing, a team none of whose robots connected, or the
    referee; None when the match played (or its play was not counted)."""
    if sim is None or not sim.finished or sim.play is None:
        return None
    play = sim.play
    minimum = timing.minimum_play_s if timing is not None else MIN_PLAYING_S
    if played_enough(play.halves_playing, play.playing_s, minimum):
        return None
    played = (f"{play.playing_s:g} s of PLAYING, halves in PLAYING: "
              f"{list(play.halves_playing) or 'none'}; the minimum of play is {minimum:g} s")
    if timing is not None:
        problem = timing_problem(timing.half_duration_s, minimum_s=minimum)
        if problem is not None:
            return Failure(failure_class=FailureClass.NOT_PLAYED,
                           cause=f"the match did not play ({played}): the league's timing: "
                           f"{problem}")
    absent: list[Color] = [c for c in COLORS if _never_connected(c, robots, sim.robots)]
    if len(absent) == 1:
        return Failure(failure_class=FailureClass.TEAM_ABSENT, team=absent[0],
                       cause=f"the match did not play ({played}): no robot of {absent[0]} "
                       "ever connected to the simulator")
    if absent:
        return Failure(failure_class=FailureClass.NOT_PLAYED,
                       cause=f"the match did not play ({played}): no robot of either team "
                       "ever connected to the simulator")
    return Failure(failure_class=FailureClass.NOT_PLAYED,
                   cause=f"the match did not play ({played})")


def _never_connected(color: str, robots: list[RobotRecord],
                     api_stats: dict[str, RobotApiStats]) -> bool:
    team = [r for r in robots if r.color == color]
    return bool(team) and not any(_connected(api_stats, r.key) for r in team)


def _connected(api_stats: dict[str, RobotApiStats], key: str) -> bool:
    """Whether the robot ``key`` ever connected to the simulator's robot API."""
    stats = api_stats.get(key)
    return bool(stats is not None and stats.get("connects"))


def team_warnings(robots: list[RobotRecord], api_stats: dict[str, RobotApiStats]) -> list[str]:
    """What a score alone hides: a team whose started robots all exited during the game, or
    none of which ever connected to the simulator."""
    warnings = []
    for color in ("red", "blue"):
        started = [r for r in robots if r.color == color and r.entry.container is not None]
        if not started:
            continue
        if all(r.entry.exited_during_game for r in started):
            warnings.append(f"every robot of {color} exited during the game ("
                            + ", ".join(f"{r.key}: exit code {r.entry.exit_code}"
                                        for r in started)
                            + ")")
        if not any(_connected(api_stats, r.key) for r in started):
            warnings.append(f"no robot of {color} ever connected to the simulator")
    return warnings


def write_results(out_dir: Path, results: MatchResults) -> Path:
    return results.write(out_dir / files.RESULTS)


def write_report(out_dir: Path, failure: Failure | None,
                 logs_cut: tuple[dict[str, str], ...] = ()) -> Path:
    """Written last: its presence means the match folder is complete. ``logs_cut``: the teams'
    logs that were cut at their limit or lost, with the reason."""
    return MatchReport.of(failure, logs_cut).write(out_dir / files.REPORT)


__all__ = [
    "Failure",
    "FailureClass",
    "RobotRecord",
    "build_results",
    "play_failure",
    "team_warnings",
    "write_report",
    "write_results",
]
