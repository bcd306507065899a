"""``hlvs scrimmage`` end to end: the real simulator image, stub robots, telemetry on the control
network; the game reaches FINISHED and the output folder is complete."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest

from hlvs.cli import main as hlvs
from orchestrator.engine.gpu import device_files
from orchestrator.errors import OrchestratorError
from orchestrator.match import gpu

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_short_scrimmage_plays_to_finished(tmp_path: Path, runtime: Any,
                                           capsys: pytest.CaptureFixture[str],
                                           monkeypatch: pytest.MonkeyPatch) -> None:
    """From a working directory with a relative ``--out``, as ``make scrimmage`` runs it: the
    folders reach Docker as absolute bind-mount sources. On a host without an NVIDIA GPU the
    default ``gpu`` setting (``auto``) plays it with the cameras on the CPU and says so once (the
    other ``gpu`` cases are in test_match_gpu.py)."""
    try:
        from orchestrator.project_images import project_image

        project_image("simulator")
        project_image("stub")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")
    out = tmp_path / "matches" / "scrim"
    match_id = "scrim-test"
    without_gpu = not device_files()
    monkeypatch.setattr(gpu, "_said", set())  # said once per process: this test's process
    monkeypatch.chdir(tmp_path)
    try:
        code = hlvs(["scrimmage", "--out", "matches/scrim", "--half-duration", "4",
                     "--ready-duration", "2", "--minimum-play", "0",
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
    if without_gpu:
        said = [line for line in printed.err.splitlines() if "gpu auto" in line]
        assert len(said) == 1, printed.err[-3000:]
        assert said[0].endswith("gpu auto: no NVIDIA device file (/dev/nvidia0, ...) on this "
                                "host; the simulator renders cameras on the CPU (OSMesa)")
        cameras = json.loads((out / "public" / "sim_result.json").read_text())["cameras"]
        assert cameras["frames"] > 0  # the stubs asked for images and got them
        assert cameras["gl_backend"] == "osmesa"
        assert "llvmpipe" in cameras["gl_renderer"] and cameras["gl_vendor"]
        simulator_log = (out / "simulator" / "stderr.log").read_text()
        assert "robot cameras render with osmesa: llvmpipe" in simulator_log


def test_scrimmage_with_a_team_of_wolfgang_models_plays_to_the_end(
    tmp_path: Path, runtime: Any, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Red plays with the Wolfgang model package (URDF and meshes mounted read-only into the
    simulator), blue with the built-in robot; the stub drives both through the robot API."""
    try:
        from orchestrator.project_images import project_image

        project_image("simulator")
        project_image("stub")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")
    wolfgang = Path(__file__).resolve().parents[3] / "configs/examples/robots/wolfgang"
    match_id = "scrim-wolfgang"
    monkeypatch.chdir(tmp_path)
    try:
        code = hlvs(["scrimmage", "--out", "wolf", "--red-model", str(wolfgang),
                     "--half-duration", "4", "--ready-duration", "2",
                     "--minimum-play", "0", "--wait-before-ready", "1", "--grace", "2",
                     "--match-id", match_id, "--json"])
        printed = capsys.readouterr()
    finally:
        hlvs(["cleanup", "--match", match_id])
    assert code == 0, printed.err[-3000:]
    assert "red robots: the stub robot commands the built-in robot's motors" in printed.err
    out = tmp_path / "wolf"
    printed_results = json.loads(printed.out)  # --json: stdout holds the one JSON document
    assert printed_results["exit_code"] == 0 and printed_results["out_dir"] == str(out)
    results = json.loads((out / "results.json").read_text())
    assert printed_results["final_state"] == results["final_state"]
    assert results["final_state"] == "FINISHED" and results["status"] == "success"
    spec = json.loads((out / "simulator" / "match_spec.json").read_text())
    models = {t["color"]: t["players"][0]["model"] for t in (spec["red"], spec["blue"])}
    assert models["blue"] == "kid-default"
    assert models["red"].startswith("/opt/hlvs/team-models/wolfgang-")
    team = json.loads((out / "config" / "team_red.json").read_text())
    assert team["players"]["1"]["model"] == str(wolfgang)
    assert runtime.list_project(match_id=match_id) == []


def test_adult_scrimmage_plays_adult_robots_on_the_adult_field(
    tmp_path: Path, runtime: Any, capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """``--class adult``: an ADULT game.json, the simulator builds the 14 x 9 m field, both
    teams play the adult-size built-in robot, placed on the adult touch line."""
    try:
        from orchestrator.project_images import project_image

        project_image("simulator")
        project_image("stub")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")
    match_id = "scrim-adult"
    monkeypatch.chdir(tmp_path)
    try:
        code = hlvs(["scrimmage", "--out", "adult", "--class", "adult", "--half-duration", "4",
                     "--ready-duration", "2", "--minimum-play", "0", "--wait-before-ready", "1",
                     "--grace", "2", "--match-id", match_id])
        printed = capsys.readouterr()
    finally:
        hlvs(["cleanup", "--match", match_id])
    assert code == 0, printed.err[-3000:]
    out = tmp_path / "adult"
    results = json.loads((out / "results.json").read_text())
    assert results["final_state"] == "FINISHED" and results["status"] == "success"
    assert json.loads((out / "config" / "game.json").read_text())["class"] == "ADULT"
    spec = json.loads((out / "simulator" / "match_spec.json").read_text())
    assert spec["field_class"] == "adult"
    for team in (spec["red"], spec["blue"]):
        (player,) = team["players"]
        assert player["model"] == "adult-default"
        assert player["half_time_pose"]["y_m"] == -4.6  # outside the adult touch line
    assert runtime.list_project(match_id=match_id) == []

