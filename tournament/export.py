"""``hlvs schedule export``: the tournament's results for the league's website.

:func:`export_document` is one JSON document (every match with its teams, state, score and
shoot-out kept apart, the standings with their tie-breaks, the knockout bracket);
:func:`write_csv` writes one of its tables (matches or standings) as CSV with a header row.
"""

from __future__ import annotations

import csv
from datetime import UTC, datetime
from typing import Any, TextIO

from tournament.overview import bracket, score_text
from tournament.standings import standings
from tournament.state import Ledger, MatchRow

MATCH_COLUMNS = (
    "id", "kind", "stream_start", "red", "blue", "state", "played", "red_goals", "blue_goals",
    "shootout_red", "shootout_blue", "winner", "score", "logs_delivered",
)
STANDING_COLUMNS = (
    "rank", "team", "played", "won", "drawn", "lost", "goals_for", "goals_against",
    "goal_difference", "points", "decided_by",
)
TABLES = ("matches", "standings")


def _match(row: MatchRow) -> dict[str, Any]:
    result: dict[str, Any] = dict(row.result or {})
    score = result.get("score") or {}
    shootout = result.get("shootout") or {}
    played = row.state.played
    return {
        "id": row.id,
        "kind": row.kind,
        "stream_start": row.stream_start.isoformat(timespec="seconds"),
        "red": row.red,
        "blue": row.blue,
        "state": row.state.value,
        "played": played,
        "red_goals": score.get("red") if played else None,
        "blue_goals": score.get("blue") if played else None,
        "shootout_red": shootout.get("red") if played else None,
        "shootout_blue": shootout.get("blue") if played else None,
        "winner": result.get("winner_team") if played else None,
        "score": score_text(row) if played else "",
        "logs_delivered": row.state.value == "DELIVERED",
    }


def export_document(ledger: Ledger) -> dict[str, Any]:
    """The tournament's results: matches (played ones with their score and shoot-out), the
    standings of the round robin, the knockout bracket by round."""
    from tournament.controls import recorded_schedule

    schedule = recorded_schedule(ledger)
    rows = ledger.rows()
    table = standings(rows, [t.name for t in schedule.teams], seed=schedule.name)
    return {
        "name": schedule.name,
        "exported_at": datetime.now(UTC).isoformat(timespec="seconds"),
        "matches": [_match(row) for row in rows],
        "standings": [{"rank": n, **s.as_dict()} for n, s in enumerate(table, start=1)],
        "bracket": bracket(schedule),
    }


def write_csv(document: dict[str, Any], table: str, out: TextIO) -> None:
    """One table of :func:`export_document` as CSV (booleans ``true``/``false``, no value
    empty)."""
    columns = MATCH_COLUMNS if table == "matches" else STANDING_COLUMNS
    writer = csv.DictWriter(out, fieldnames=columns, lineterminator="\n")
    writer.writeheader()
    for record in document[table]:
        writer.writerow({k: _cell(record.get(k)) for k in columns})


def _cell(value: Any) -> str:
    if value is None:
        return ""
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)
