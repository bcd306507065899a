"""What the operator sees of every match: ``hlvs schedule status`` (and ``--watch``).

A match line tells "played" (PLAYED and after: the score is final) apart from "logs delivered"
(DELIVERED: every set reached its target) and names every log set's own state.
"""

from __future__ import annotations

from orchestrator.schedule.logs import summary
from orchestrator.schedule.state import Ledger, MatchRow, ScheduledMatchState

S = ScheduledMatchState


def score_text(row: MatchRow) -> str:
    """``2-1``, ``1-1 (shoot-out 3-2)``, or "" when there is no score."""
    result = row.result or {}
    score = result.get("score") or {}
    if score.get("red") is None or score.get("blue") is None:
        return ""
    text = f"{score['red']}-{score['blue']}"
    shootout = result.get("shootout")
    if isinstance(shootout, dict) and shootout.get("red") is not None:
        text += f" (shoot-out {shootout['red']}-{shootout['blue']})"
    return text


def logs_text(row: MatchRow) -> str:
    if row.logs:
        return summary(list(row.logs))
    if row.state.played:
        return "logs: pending"
    return ""


def status_line(row: MatchRow) -> str:
    score = score_text(row)
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


def status_lines(ledger: Ledger) -> list[str]:
    return [status_line(row) for row in ledger.rows()]
