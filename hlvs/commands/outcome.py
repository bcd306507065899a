"""What a played match tells the user: one line (or ``results.json`` with ``--json``) and the
exit code, the same for a match played here (:mod:`hlvs.commands.play`) and one played in a
pool (:mod:`hlvs.commands.pooled`)."""

from __future__ import annotations

import json
import sys
from pathlib import Path
from typing import TYPE_CHECKING

from contracts import FailureClass, files
from orchestrator import ExitCode, InfrastructureError

if TYPE_CHECKING:
    from orchestrator.match import MatchOutcome


def _shown(path: Path) -> str:
    """``path`` relative to the current directory when it is below it, else absolute."""
    try:
        return str(path.relative_to(Path.cwd()))
    except ValueError:
        return str(path)


def watch_hint(out_dir: Path) -> list[str]:
    """Where to watch a played match: the viewer and the video command (empty: no replay)."""
    replay = out_dir / "public" / files.REPLAY
    if not replay.is_file():
        return []
    return [
        f"watch it in the browser:  hlvs view {_shown(out_dir)}",
        f"or as a video:            hlvs render {_shown(replay)} -o match.mp4",
    ]


def summarize(outcome: MatchOutcome, *, as_json: bool = False) -> int:
    """Print the outcome (one line, or results.json with ``as_json``) and return its exit code:
    0 played, 4 decided by forfeit, 1 failed, 3 infrastructure, 130 interrupted."""
    results = outcome.results
    score = (results.score if results is not None else None) or {}
    failure = outcome.failure
    forfeit = results.forfeit if results is not None else None
    if failure is None:
        code = ExitCode.FORFEIT if forfeit else ExitCode.OK
    elif failure.failure_class is FailureClass.INTERRUPTED:
        code = ExitCode.INTERRUPTED
    elif failure.failure_class is FailureClass.INFRASTRUCTURE:
        code = ExitCode(InfrastructureError.exit_code)
    else:
        code = ExitCode.FAILED
    if as_json:
        document = results.to_dict() if results is not None else {}
        document.setdefault("match_id", outcome.match_id)
        document["out_dir"] = str(outcome.out_dir)
        document["exit_code"] = int(code)
        if failure is not None:
            document.setdefault(
                "failure", {"class": failure.failure_class.value, "cause": failure.cause}
            )
        print(json.dumps(document, indent=2, sort_keys=True, default=str))
        return code
    if failure is None:
        if forfeit:
            what = f"{forfeit.team} forfeits, winner {forfeit.winner}"
        else:
            winner = results.winner if results is not None else None
            what = f"red {score.get('red')} - {score.get('blue')} blue, winner {winner}"
        print(f"match {outcome.match_id}: {what}; results in {outcome.out_dir}")
        for line in watch_hint(outcome.out_dir):
            print(line)
        return code
    print(f"match {outcome.match_id} failed ({failure.failure_class.value}): {failure.cause}; "
          f"results in {outcome.out_dir}", file=sys.stderr)
    return code


__all__ = ["summarize", "watch_hint"]
