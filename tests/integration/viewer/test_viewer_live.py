"""A real scrimmage (Docker, stub robots) watched live in Chromium through ``hlvs view`` (zenoh
telemetry on the control network -> server-sent events), then its replay in the 3D viewer."""

from __future__ import annotations

import subprocess
import sys
import time
import uuid
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from simulator.replay import ReplayFile
from tests.integration.viewer.conftest import hlvs_view, screenshot

pytestmark = [pytest.mark.docker, pytest.mark.root, pytest.mark.browser, pytest.mark.slow]
HLVS = str(Path(sys.executable).parent / "hlvs")


def _live(page: Any) -> list[float]:
    values: list[float] = page.evaluate("[hlvsLive.updates, hlvsLive.simTimeMs]")
    return values


def test_live_view_follows_a_running_scrimmage_and_its_replay_plays(
    tmp_path: Path, page: Any, docker_client: Any
) -> None:
    try:
        from orchestrator.errors import OrchestratorError
        from orchestrator.project_images import project_image

        project_image("simulator")
        project_image("stub")
    except (ImportError, OrchestratorError) as exc:
        pytest.skip(f"project images unavailable: {exc}")
    out = tmp_path / "scrim"
    match_id = f"viewer-live-{uuid.uuid4().hex[:6]}"
    scrimmage = subprocess.Popen(
        [HLVS, "scrimmage", "--out", str(out), "--half-duration", "5",
         "--ready-duration", "8", "--minimum-play", "0", "--wait-before-ready",
         "1", "--grace", "2", "--match-id", match_id],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
    )  # fmt: skip
    try:
        deadline = time.monotonic() + 120
        while not (out / "simulator" / "match_spec.json").is_file():
            assert scrimmage.poll() is None and time.monotonic() < deadline, "no match started"
            time.sleep(0.2)
        with hlvs_view(out) as urls:
            assert urls == [f"{urls[0].split('/watch/')[0]}/watch/live/{match_id}"]
            page.goto(urls[0])
            page.wait_for_function(
                "window.hlvsLive && hlvsLive.hasScene && hlvsLive.updates >= 5", timeout=120_000
            )
            first = _live(page)
            page.wait_for_function(
                f"hlvsLive.updates > {first[0] + 10} && hlvsLive.simTimeMs > {first[1] + 1000}",
                timeout=120_000,
            )
            page.wait_for_function(  # both robots connected (they start within seconds)
                "document.querySelectorAll('[data-testid=health] tr.up').length === 2",
                timeout=60_000,
            )
            health = page.locator("[data-testid=health] tr[data-robot]").evaluate_all(
                "rows => rows.map(r => [r.dataset.robot, r.cells[1].innerText])"
            )
            assert sorted(health) == [["blue-1", "connected"], ["red-1", "connected"]]
            assert "real-time factor" in page.locator("[data-testid=live-status]").inner_text()
            screenshot(page, "live-scrimmage")
            output, _ = scrimmage.communicate(timeout=300)
            assert scrimmage.returncode == 0, output[-3000:]
            page.locator("[data-testid=replay-link]").wait_for(timeout=30_000)
    finally:
        if scrimmage.poll() is None:
            scrimmage.kill()
            scrimmage.wait()
        subprocess.run([HLVS, "cleanup", "--match", match_id], capture_output=True, timeout=120)

    with ReplayFile(out / "public" / "replay.hlvsrec") as replay:
        frame = next(f for f in replay.frames() if f.sim_time_ms == 6000)
        names = replay.header.body_names
    with hlvs_view(out) as urls:
        page.goto(urls[0])
        page.wait_for_function("window.hlvsViewer && hlvsViewer.ready", timeout=30_000)
        page.evaluate("hlvsViewer.seek(6000)")
        page.wait_for_function("hlvsViewer.time === 6000 && hlvsViewer.ready")
        shown = np.asarray(page.evaluate("hlvsViewer.poses()"), dtype=np.float32)
        np.testing.assert_allclose(shown.reshape(-1, 7), frame.poses, atol=1e-5)
        for team in ("red", "blue"):
            torso = frame.poses[names.index(f"{team}_1/torso"), :3].tolist()
            r, g, b, _ = page.evaluate("p => hlvsViewer.pixel(p)", torso)
            assert (r > 1.6 * max(g, b)) if team == "red" else (b > 1.6 * r), (team, r, g, b)
        screenshot(page, "replay-real-scrimmage")
