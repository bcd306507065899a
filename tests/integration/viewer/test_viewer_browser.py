"""The replay viewer in Chromium: it loads, draws robots and ball where the replay has them at a
sought time, jumps to a goal from the timeline, plots the API statistics, reads version 1."""

from __future__ import annotations

from io import BytesIO
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from simulator.replay import ReplayFile
from tests.integration.viewer.conftest import hlvs_view, screenshot
from tests.unit.viewer.replays import GOAL_MS, record_match

pytestmark = pytest.mark.browser
V1_FIXTURE = Path(__file__).parents[2] / "unit" / "replay" / "fixtures" / "v1-two-robots.hlvsrec"
SEEK_MS = 1520  # a recorded frame: the poses on screen are the recorded ones, not interpolated


@pytest.fixture(scope="module")
def match(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("browser") / "match-b"
    record_match(folder)
    return folder


def _open(page: Any, url: str) -> None:
    page.goto(url)
    page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)


def _is_team(rgb: list[int], team: str) -> bool:
    r, g, b = rgb[:3]
    return r > 1.6 * g and r > 1.6 * b if team == "red" else b > 1.6 * r and b > 1.2 * g


def test_robots_and_ball_are_drawn_where_the_replay_has_them(page: Any, match: Path) -> None:
    with ReplayFile(match / "public" / "replay.hlvsrec") as replay:
        frame = next(f for f in replay.frames() if f.sim_time_ms == SEEK_MS)
        names = replay.header.body_names
        robots = [(r.team, names.index(f"{r.key}/torso")) for r in replay.header.robots]
        ball = frame.poses[names.index("ball"), :3].tolist()
    with hlvs_view(match) as urls:
        _open(page, urls[0])
        page.locator("[data-testid=seek]").fill(str(SEEK_MS))
        page.wait_for_function(f"window.hlvsViewer.time === {SEEK_MS} && window.hlvsViewer.ready")
        page.wait_for_timeout(300)
        shown = np.asarray(page.evaluate("window.hlvsViewer.poses()"), dtype=np.float32)
        np.testing.assert_allclose(shown.reshape(-1, 7), frame.poses, atol=1e-5)
        for team, body in robots:
            torso = frame.poses[body, :3].tolist()
            rgb = page.evaluate("p => window.hlvsViewer.pixel(p)", torso)
            assert _is_team(rgb, team), f"{names[body]} at {torso}: drawn colour {rgb}"
        rgb = page.evaluate("p => window.hlvsViewer.pixel(p)", ball)
        assert not (rgb[1] > rgb[0] + 30 and rgb[1] > rgb[2] + 30), f"grass at the ball: {rgb}"
        grass = page.evaluate("p => window.hlvsViewer.pixel(p)", [1.2, -2.2, 0.0])
        assert grass[1] > grass[0] + 30 and grass[1] > grass[2] + 30, f"no grass: {grass}"
        assert page.locator("[data-testid=game-state]").inner_text() == "PLAYING 1st half"
        screenshot(page, "replay-sought")


PAUSE_PAST = """(t) => new Promise((resolve, reject) => {
    const until = performance.now() + 15000;
    const tick = () => {
        if (window.hlvsViewer.time > t) {
            document.querySelector("[data-testid=play]").click();
            resolve();
        } else if (performance.now() > until) {
            reject(new Error(`playback never passed ${t} ms`));
        } else {
            requestAnimationFrame(tick);
        }
    };
    tick();
})"""


def test_the_timeline_jumps_to_the_goal_and_playback_runs(page: Any, match: Path) -> None:
    with hlvs_view(match) as urls:
        _open(page, urls[0])
        assert page.locator("[data-testid=score-red]").inner_text() == "0"
        page.locator("[data-testid=mark-goal]").click()
        page.wait_for_function("window.hlvsViewer.ready")
        assert page.evaluate("window.hlvsViewer.time") == GOAL_MS - 2000
        page.locator("[data-testid=speed]").select_option("0.5")
        page.locator("[data-testid=play]").click()
        # pause just past the goal, from within the page: 0.5x leaves 0.7 s of wall time before
        # the replay's end, which a click sent from here after a wait could miss on a busy host
        page.evaluate(PAUSE_PAST, GOAL_MS + 40)
        paused_at = page.evaluate("window.hlvsViewer.time")
        assert GOAL_MS < paused_at < 3000
        page.wait_for_timeout(100)  # the last frame of the playback is drawn
        drawn = page.evaluate("window.hlvsViewer.frames")
        page.wait_for_timeout(300)
        assert page.evaluate("window.hlvsViewer.time") == paused_at
        assert page.evaluate("window.hlvsViewer.frames") == drawn  # paused: nothing redrawn
        assert page.locator("[data-testid=score-red]").inner_text() == "1"
        events = page.locator("[data-testid=events] li button").all_inner_texts()
        assert events == ["00:02 goal red 2"]
        assert page.locator("[data-testid=event-number]").all_inner_texts() == ["1."]
        series = page.locator("[data-testid=plot-latency] polyline").evaluate_all(
            "ls => ls.map(l => [l.dataset.series, l.getAttribute('points').split(' ').length])"
        )
        assert series == [["red-1", 3]]
        assert page.locator("[data-testid=plot-rtf] polyline").count() == 1
        screenshot(page, "replay-goal")


def test_a_version_1_replay_plays_in_the_browser(page: Any) -> None:
    with hlvs_view(V1_FIXTURE) as urls:
        _open(page, urls[0])
        assert page.evaluate("window.hlvsViewer.meta.version") == 1
        page.locator("[data-testid=play]").click()
        page.wait_for_function("window.hlvsViewer.time >= 480", timeout=15_000)
        assert page.locator("[data-testid=score-red]").inner_text() == "1"
        screenshot(page, "replay-version-1")


LONG = "a pushing foul far from the ball that the referee describes at length, so it wraps"
MANY_EVENTS = tuple(
    {"type": "penalty", "team": "blue", "player": 1 + k % 4, "sim_time_ms": 200 + 160 * k,
     "reason": LONG if k == 11 else "pushing"} for k in range(12)
) + ({"type": "state", "team": None, "player": None, "sim_time_ms": GOAL_MS,
      "reason": "goal: READY"},)


@pytest.fixture(scope="module")
def busy_match(tmp_path_factory: pytest.TempPathFactory) -> Path:
    folder = tmp_path_factory.mktemp("browser") / "match-busy"
    record_match(folder, events=MANY_EVENTS)
    return folder


def test_event_list_timeline_and_plots_line_up(page: Any, busy_match: Path) -> None:
    """Numbers 10 and up are whole and stay beside the first line of a wrapped event; the goal
    mark is above the state mark at the same time; a mark is where the slider's thumb is at its
    time; the plots' x axis is match time with a playhead at the replay's time."""
    with hlvs_view(busy_match) as urls:
        _open(page, urls[0])
        numbers = page.locator("[data-testid=event-number]")
        assert numbers.count() == 14 and numbers.nth(12).inner_text() == "13."
        for n in range(numbers.count()):  # never clipped: ".0", ".1" for 10 and 11 before
            assert numbers.nth(n).evaluate("e => e.scrollWidth <= e.clientWidth"), n
        wrapped = page.locator("[data-testid=events] li", has_text="at length")
        text_box = wrapped.locator("button").bounding_box()
        number_box = wrapped.locator("[data-testid=event-number]").bounding_box()
        assert text_box["height"] > 1.8 * number_box["height"]  # it does wrap
        assert abs(number_box["y"] - text_box["y"]) < 4  # the number is on the first line

        goal = page.locator("[data-testid=mark-goal]").bounding_box()
        on_top = page.evaluate("([x, y]) => document.elementFromPoint(x, y).dataset.testid",
                               [goal["x"] + goal["width"] / 2, goal["y"] + goal["height"] / 2])
        assert on_top == "mark-goal"

        page.locator("[data-testid=seek]").fill(str(GOAL_MS))
        page.wait_for_function(f"window.hlvsViewer.time === {GOAL_MS}")
        seek = page.locator("[data-testid=seek]").bounding_box()
        strip = page.locator("[data-testid=timeline]").bounding_box()
        assert abs(seek["width"] - strip["width"]) < 1 and abs(seek["x"] - strip["x"]) < 1
        row = page.locator("[data-testid=seek]").screenshot()
        pixels = np.asarray(Image.open(BytesIO(row)).convert("RGB"), dtype=np.int32)
        # the thumb's columns: dark from top to bottom, away from the focus ring at the ends
        dark = np.where((pixels.sum(axis=2) < 200).sum(axis=0) > 0.6 * pixels.shape[0])[0]
        dark = dark[(dark > 3) & (dark < pixels.shape[1] - 4)]
        thumb_x = seek["x"] + dark.mean()
        goal = page.locator("[data-testid=mark-goal]").bounding_box()
        assert abs(thumb_x - (goal["x"] + goal["width"] / 2)) <= 2.0, (thumb_x, goal)

        label = page.locator("[data-testid=plot-rtf] text").all_text_contents()
        assert "3 s (match time)" in label
        head = page.locator("[data-testid=plot-rtf-playhead]")
        page.wait_for_function("document.querySelector('[data-testid=plot-rtf-playhead]')"
                               ".getAttribute('x1') !== '36'")
        expected = 36 + GOAL_MS / 3000 * (420 - 36 - 8)
        assert abs(float(head.get_attribute("x1")) - expected) < 0.5
        screenshot(page, "replay-events-timeline-plots")


def test_the_live_page_of_a_match_that_is_over_links_its_replay(
        page: Any, tmp_path: Path) -> None:
    """``hlvs view`` of a match folder whose telemetry is gone but whose replay was written
    (the match ended, its output not collected): the live page says it ended and links the
    replay, with the teams' names, instead of an empty scene."""
    import socket
    from dataclasses import replace

    from orchestrator.config import load_game, to_match_spec
    from tests.unit.config.conftest import EXAMPLES

    folder = tmp_path / "ended"
    recorded = record_match(tmp_path / "recorded", seconds=1.0)
    out = folder / "simulator" / "out"
    out.mkdir(parents=True)
    recorded.replace(out / "replay.hlvsrec")
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port = sock.getsockname()[1]
    spec = to_match_spec(load_game(EXAMPLES / "scrimmage_1v1" / "game.json"),
                         robot_addresses={}, telemetry_listen=f"tcp/127.0.0.1:{port}")
    spec = replace(spec, match_id="ended-1", red=replace(spec.red, name="Ants"),
                   blue=replace(spec.blue, name="Bees"))
    spec.write(folder / "simulator" / "match_spec.json")
    with hlvs_view(folder) as urls:
        live = next(u for u in urls if "/watch/live/" in u)
        page.goto(live)
        page.wait_for_selector("[data-testid=replay-link]", timeout=60_000)
        assert page.locator("[data-testid=live-status]").inner_text().startswith(
            "This match has ended (Ants v Bees).")
        assert page.locator("canvas").count() == 0
        screenshot(page, "view-live-ended")
        page.locator("[data-testid=replay-link]").click()
        page.wait_for_function("window.hlvsViewer && window.hlvsViewer.ready", timeout=30_000)
        assert page.locator("[data-testid=team-red]").inner_text() == "Ants"


def test_a_failed_first_request_is_tried_again_and_a_dead_server_is_said(
        page: Any, match: Path) -> None:
    """The page's first request (is this the service?) failing at the network (a connection
    the server closed as the browser reused it): tried again, the replay shows; failing every
    time, the page says so instead of staying blank (and raises nothing)."""
    aborted: list[str] = []

    def flaky(route: Any) -> None:
        if len(aborted) < 2:
            aborted.append(route.request.url)
            route.abort("connectionreset")
        else:
            route.continue_()

    with hlvs_view(match) as urls:
        page.route("**/v1/health", flaky)
        _open(page, urls[0])
        assert len(aborted) == 2
        page.unroute("**/v1/health")
        page.route("**/v1/health", lambda route: route.abort("connectionrefused"))
        page.goto(urls[0])
        error = page.locator("[data-testid=error]")
        error.wait_for(timeout=30_000)
        assert error.inner_text().startswith("The server does not answer (")
        assert page.evaluate("window.hlvsViewer === undefined")
