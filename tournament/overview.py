"""What the operator sees of every match: ``hlvs schedule status`` (and ``--watch``).

A match line tells "played" (PLAYED and after: the score is final) apart from "logs delivered"
(DELIVERED: every set reached its target) and names every log set's own state.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import replace
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, TypedDict
from urllib.parse import quote, urlencode

from contracts import files
from orchestrator.config import Schedule
from tournament.logs import summary
from tournament.state import Ledger, MatchRow, ScheduledMatchState


class LiveGame(TypedDict, total=False):
    """A running match's game state, as its telemetry's state message gives it."""

    state: str | None  # GameController state name
    secondary_state: str | None
    half: int | None
    phase: str
    secs_remaining: float | None
    score: dict[str, int] | None  # {"red": goals, "blue": goals}
    sim_time_ms: int


Snapshot = Callable[[Path], LiveGame | None]  # a running match's folder -> its game state

S = ScheduledMatchState


def score_text(row: MatchRow) -> str:
    """``2-1``, ``1-1 (shoot-out 3-2)``, or "" when there is no score."""
    if row.result is None:
        return ""
    result = row.result
    score = result.get("score") or {}
    if score.get("red") is None or score.get("blue") is None:
        return ""
    text = f"{score['red']}-{score['blue']}"
    shootout = result.get("shootout")
    if isinstance(shootout, dict) and shootout.get("red") is not None:
        text += f" (shoot-out {shootout['red']}-{shootout['blue']})"
    return text


def with_store(row: MatchRow, waiting: set[tuple[str, str]]) -> MatchRow:
    """The row with each failed set that is no longer in the log store marked ``gone`` (a
    retry not yet made will tell whether it was delivered by hand or pruned; a LOGS_FAILED
    match is settled first, :func:`tournament.jobs.settle_hand_deliveries`)."""
    if not any(e.state in ("failed", "retrying") for e in row.logs):
        return row
    logs = tuple(
        replace(e, state="gone", cause="no longer in the log store (delivered by 'hlvs logs "
                "deliver' or pruned)")
        if e.state in ("failed", "retrying") and (row.id, e.team) not in waiting else e
        for e in row.logs)
    return replace(row, logs=logs)


def settle(ledger: Ledger, schedule: Schedule) -> None:
    from tournament.jobs import settle_hand_deliveries

    settle_hand_deliveries(ledger, schedule)


def waiting_sets(schedule: Schedule) -> set[tuple[str, str]]:
    """(match id, team) of the sets waiting in the log store (the store has the matches'
    league ids, :meth:`~orchestrator.config.Schedule.league_match_id`)."""
    from orchestrator.delivery import pending_status

    ours = {schedule.league_match_id(m.id): m.id for m in schedule.matches}
    return {(ours[s.match_id], s.team) for s in pending_status(schedule.log_store)
            if s.match_id in ours}


def logs_text(row: MatchRow) -> str:
    if row.logs:
        return summary(list(row.logs))
    if row.state.played:
        return "logs: pending"
    return ""


def clock_text(live: LiveGame | None) -> str:
    """``2-1 PLAYING 1st half 07:31`` of a running match's game state."""
    if not live:
        return ""
    score = live.get("score") or {}
    half = {1: "1st half", 2: "2nd half"}.get(live.get("half") or 0, "")
    secondary = live.get("secondary_state")
    parts = [f"{score.get('red', '-')}-{score.get('blue', '-')}", str(live.get("state", "-"))]
    if secondary and secondary != "NORMAL":
        parts.append(str(secondary))
    if half:
        parts.append(half)
    remaining = live.get("secs_remaining")
    if isinstance(remaining, int | float):
        parts.append(f"{int(remaining) // 60:02d}:{int(remaining) % 60:02d}")
    return " ".join(parts)


def status_line(row: MatchRow, live: LiveGame | None = None) -> str:
    score = clock_text(live) if live else score_text(row)
    played = "played" if row.state.played else ""
    parts = [f"{row.id:<12} {row.state.value:<12} {row.red} v {row.blue}"]
    if score:
        parts.append(score)
    if played:
        parts.append(f"[{played}; {logs_text(row)}]")
    if row.request:
        parts.append(f"(requested: {row.request.get('action')})")
    if row.note and not (played and row.note.startswith("logs:")):
        parts.append(row.note)
    return "  ".join(parts).rstrip()


def status_lines(ledger: Ledger, *, snapshot: Snapshot | None = None) -> list[str]:
    """One line per match; a running match shows its score and clock when ``snapshot`` (see
    :func:`viewer.snapshot.game_snapshot`) can read its telemetry."""
    from tournament.controls import recorded_schedule

    schedule = recorded_schedule(ledger)
    settle(ledger, schedule)
    waiting = waiting_sets(schedule)
    lines = []
    for row in ledger.rows():
        row = with_store(row, waiting)
        live = None
        if snapshot is not None and row.state is S.PLAYING:
            live = snapshot(match_folder(ledger, row.id))
        lines.append(status_line(row, live))
    return lines


def match_folder(ledger: Ledger, match_id: str, schedule: Schedule | None = None) -> Path:
    """``<output_dir>/<match id>/match``: where the match plays (and its public files end)."""
    if schedule is None:
        from tournament.controls import recorded_schedule

        schedule = recorded_schedule(ledger)
    return schedule.output_dir / match_id / "match"


def replay_path(folder: Path) -> Path | None:
    for candidate in (folder / "public" / files.REPLAY,  # as hlvs match leaves it
                      folder / "simulator" / files.OUT_DIR / files.REPLAY):
        if candidate.is_file():
            return candidate
    return None


def bracket(schedule: Schedule) -> list[list[str]]:
    """The knockout matches by round: a match is one round after the matches it takes its
    teams from."""
    knockout = {m.id: m for m in schedule.matches if m.kind == "knockout"}
    depth: dict[str, int] = {}

    def depth_of(match_id: str, seen: frozenset[str] = frozenset()) -> int:
        if match_id not in depth:
            match = knockout.get(match_id)
            refs = [] if match is None else [
                r for s in (match.red, match.blue) for r in (s.winner_of, s.loser_of)
                if r and r not in seen]
            depth[match_id] = 1 + max((depth_of(r, seen | {match_id}) for r in refs), default=0)
        return depth[match_id]

    for match_id in knockout:
        depth_of(match_id)
    depth = {k: v for k, v in depth.items() if k in knockout}
    rounds: list[list[str]] = [[] for _ in range(max(depth.values(), default=0))]
    for match_id, n in depth.items():
        rounds[n - 1].append(match_id)
    return rounds


def tournament_overview(ledger: Ledger, *, snapshot: Snapshot | None = None,
             links: str = "/watch/tournament") -> dict[str, Any]:
    """Everything the operator's page shows: the tournament's name, every match (state, times,
    score, live clock, log states, links to the live view and the replay), the standings with
    their tie-breaks, the knockout bracket, whether a scheduler runs (its heartbeat), and the
    warnings: "scheduler not running since ..." and those about the schedule file."""
    from tournament.controls import file_differences, recorded_schedule
    from tournament.notify import scheduler_state
    from tournament.standings import standings

    schedule = recorded_schedule(ledger)
    alive = scheduler_state(ledger)
    settle(ledger, schedule)
    rows = ledger.rows()
    waiting = waiting_sets(schedule)
    matches = []
    for row in (with_store(r, waiting) for r in rows):
        folder = match_folder(ledger, row.id, schedule)
        live = None
        if snapshot is not None and row.state is S.PLAYING:
            live = snapshot(folder)
        names = {"red": row.red, "blue": row.blue}
        query = "?" + urlencode(names)
        watch: dict[str, str] = {}
        if row.state is S.PLAYING and (folder / "simulator" / files.MATCH_SPEC).is_file():
            watch["live"] = f"{links}/live/{quote(row.id)}{query}"
        if row.state is not S.PLAYING and replay_path(folder) is not None:
            watch["replay"] = f"{links}/replay/{quote(row.id)}{query}"
        matches.append({
            **row.as_dict(),
            "score_text": score_text(row),
            "logs_text": logs_text(row),
            "live": live,
            "clock_text": clock_text(live),
            "watch": watch,
        })
    return {
        "name": schedule.name,
        "updated_at": datetime.now(UTC).isoformat(timespec="seconds"),
        "matches": matches,
        "standings": [s.as_dict() for s in standings(
            rows, [t.name for t in schedule.teams], seed=schedule.name)],
        "bracket": bracket(schedule),
        "scheduler": alive.as_dict(),
        "warnings": ([alive.text] if alive.waiting else []) + file_differences(ledger),
    }
