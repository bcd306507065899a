"""A short bench match: a scrimmage's files (short READY, no minimum play) with the bench's
game fields, played by ``hlvs match`` in a process of its own (``bench hog``, ``bench
runtime``)."""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from contracts import files
from contracts.match_results import MatchResults


def scrimmage_files(folder: Path, *, match_id: str, half_s: float, stepping: str,
                    max_rtf: float, options: Sequence[str] = (),
                    fields: dict[str, Any] | None = None,
                    limits: dict[str, Any] | None = None) -> Path:
    """game.json (returned) and the team files of a scrimmage in ``folder``: ``options`` added
    to the scrimmage's command line, ``fields`` and ``limits`` set in game.json."""
    from orchestrator import add_scrimmage_arguments
    from orchestrator.match import scrimmage

    parser = argparse.ArgumentParser()
    add_scrimmage_arguments(parser)
    args = parser.parse_args([
        "--match-id", match_id, "--half-duration", str(half_s), "--ready-duration", "5",
        "--minimum-play", "0", "--wait-before-ready", "1", "--grace", "1", *options,
    ])
    game = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args), folder)
    data = json.loads(game.read_text())
    data.update(fields or {})
    data["stepping"] = stepping
    data["maximum_real_time_factor"] = max_rtf
    data.setdefault("limits", {}).update(limits or {})
    game.write_text(json.dumps(data, indent=2))
    return game


def play(bench: str, game: Path, out: Path, *, match_id: str,
         match_args: Sequence[str] = ()) -> MatchResults:
    """``hlvs match GAME --out OUT`` and its results; a failed match ends the bench, naming it."""
    done = subprocess.run([sys.executable, "-m", "hlvs", "match", str(game), "--out", str(out),
                           *match_args], capture_output=True, text=True, timeout=900,
                          check=False)
    if done.returncode != 0:
        raise SystemExit(f"hlvs bench {bench}: match {match_id} failed ({done.returncode}): "
                         f"{done.stderr.strip().splitlines()[-1:]}")
    return MatchResults.load(out / files.RESULTS)
