"""``hlvs scrimmage`` end to end: the real simulator image, stub robots, telemetry on the control
network; the game reaches FINISHED and the output folder is complete."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from orchestrator.cli import main as hlvs
from orchestrator.errors import OrchestratorError

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_short_scrimmage_plays_to_finished(tmp_path: Path, runtime: Any,
                                           capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """From a working directory with a relative ``--out``, as ``make scrimmage`` runs it: the
    folders reach Docker as absolute bind-mount sources."""
    try:
        from orchestrator.images import project_image

        project_image("simulator")
        project_image("stub")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")
    out = tmp_path / "matches" / "scrim"
    match_id = "scrim-test"
    monkeypatch.chdir(tmp_path)
    try:
        code = hlvs(["scrimmage", "--out", "matches/scrim", "--half-duration", "4",
                     "--wait-before-ready", "1", "--grace", "2", "--match-id", match_id])
    finally:
        hlvs(["cleanup", "--match", match_id])
    printed = capsys.readouterr()
    assert code == 0, printed.err[-3000:]
    assert f"match {match_id}:" in printed.out and f"results in {out}" in printed.out
    # Where to watch it, with paths as typed from the working directory.
    assert "hlvs view matches/scrim\n" in printed.out
    assert "hlvs render matches/scrim/public/replay.hlvsrec -o match.mp4" in printed.out
    assert json.loads((out / "report.json").read_text()) == {"status": "success"}
    results = json.loads((out / "results.json").read_text())
    assert results["final_state"] == "FINISHED"
    assert set(results["robots"]) == {"red-1", "blue-1"}
    assert results["timings_s"]["playing"] > 0
    for name in ("replay.hlvsrec", "referee.log", "referee_events.jsonl", "gamecontroller.log",
                 "sim_result.json"):
        assert (out / "public" / name).is_file(), name
    for color in ("red", "blue"):
        assert (out / "teams" / color / "1" / "stdout.log").is_file()
        assert (out / "teams" / color / "1" / "robocup-logs").is_dir()
    assert (out / "config" / "game.json").is_file()
    assert runtime.list_project(match_id=match_id) == []
