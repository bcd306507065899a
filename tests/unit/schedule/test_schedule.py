"""The scheduler with services that need no Docker: timing, exactly-once, restarts, standings."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time
from datetime import UTC, datetime
from pathlib import Path

import pytest

from orchestrator.config.schedule import load_schedule, round_robin_fixtures
from orchestrator.errors import ConfigError
from tests.unit.schedule.fake_services import goals
from tournament import Ledger, ScheduledMatchState, run_schedule, standings

FAKE = "tests.unit.schedule.fake_services:FakeServices"
TEAMS = ["alpha", "bravo", "charlie", "delta"]


def write_credentials(path: Path) -> Path:
    """A team's log target (S3) that the fake services never reach."""
    path.write_text(json.dumps({"type": "s3", "credentials": {
        "access_id": "hlvs", "access_secret": "x", "bucket": "logs", "region": "us-east-1"}}))
    path.chmod(0o600)
    return path


def write_schedule(tmp: Path, body: str) -> Path:
    for name in TEAMS:
        (tmp / f"{name}.json").write_text(json.dumps({"name": name, "players": {}}))
    write_credentials(tmp / "logs.json")
    teams = "\n".join(
        f"  - {{name: {n}, id: {i + 1}, config: {n}.json, credentials: logs.json}}"
        for i, n in enumerate(TEAMS)
    )
    path = tmp / "schedule.yaml"
    path.write_text(f"name: test cup\noutput_dir: out\nteams:\n{teams}\n{body}")
    return path


COMPRESSED = """
timing: {pull_lead_round_robin_s: 3.0, pull_lead_knockout_s: 3.5, play_after_pull_s: 0.2,
         deliver_after_stream_s: 0.2, retry_s: 0.2}
simulator_slots: 1
"""


def services_log(schedule: Path) -> list[tuple[str, str, datetime]]:
    path = schedule.parent / "out" / "services.log"
    if not path.exists():
        return []
    out = []
    for line in path.read_text().splitlines():
        what, match_id, at = line.split()
        out.append((what, match_id, datetime.fromisoformat(at)))
    return out


def test_round_robin_fixtures_pair_every_team_once() -> None:
    matches = round_robin_fixtures({"teams": TEAMS, "first_stream": "+10s", "interval_s": 5})
    pairs = {frozenset((m.red.team, m.blue.team)) for m in matches}
    assert len(matches) == 6 and len(pairs) == 6
    assert [m.stream_start for m in matches[:3]] == ["+10s", "+15s", "+20s"]


@pytest.mark.parametrize(("defaults", "expected"), [
    ("", 1.0),  # async, the default: never waits for the robots, so real time
    ("game_defaults: {stepping: async}\n", 1.0),
    ("game_defaults: {stepping: lockstep}\n", 0.0),  # waits for them: as fast as possible
    ("game_defaults: {stepping: pipelined}\n", 0.0),
    ("game_defaults: {stepping: async, maximum_real_time_factor: 2}\n", 2.0),
])
def test_a_matchs_pace_follows_its_stepping_unless_the_schedule_says(
        tmp_path: Path, defaults: str, expected: float) -> None:
    from orchestrator.config.schedule import game_document

    match = "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1s'}\n"
    schedule = load_schedule(write_schedule(tmp_path, defaults + match))
    red, blue = schedule.teams[0], schedule.teams[1]
    game = game_document(schedule, schedule.matches[0], red, blue)
    assert game["maximum_real_time_factor"] == expected


def test_schedule_errors_name_the_field(tmp_path: Path) -> None:
    path = write_schedule(
        tmp_path,
        "matches:\n  - {id: m1, red: alpah, blue: bravo, stream_start: '+1s'}\n"
        "  - {id: m2, red: {winner_of: m9}, blue: bravo, stream_start: 'tomorrow'}\n",
    )
    with pytest.raises(ConfigError) as info:
        load_schedule(path)
    text = str(info.value)
    assert "/matches/0/red: unknown team 'alpah'" in text and 'did you mean "alpha"' in text
    assert "/matches/1/red: refers to match 'm9'" in text
    assert "/matches/1/stream_start" in text


def test_tournament_plays_each_match_once_in_its_window(tmp_path: Path) -> None:
    path = write_schedule(
        tmp_path,
        COMPRESSED
        + "fixtures:\n  round_robin: {teams: [alpha, bravo, charlie], first_stream: '+3.5s',"
        " interval_s: 1.0, stream_length_s: 0.5}\n",
    )
    state = tmp_path / "state.sqlite"
    done = threading.Event()
    thread = threading.Thread(
        target=run_schedule,
        args=(path, state),
        kwargs={"services": FAKE, "exit_when_done": True, "poll_s": 0.1, "stop": None},
    )
    thread.start()
    thread.join(timeout=60)
    done.set()
    assert not thread.is_alive(), "the schedule did not finish"
    ledger = Ledger(state)
    rows = {r.id: r for r in ledger.rows()}
    assert set(rows) == {"rr-1", "rr-2", "rr-3"}
    assert all(r.state is ScheduledMatchState.DELIVERED for r in rows.values()), rows
    log = services_log(path)
    for match_id, row in rows.items():
        steps = [(what, at) for what, mid, at in log if mid == match_id]
        kinds = [w for w, _ in steps]
        assert kinds == ["pull", "play-start", "play-end", "deliver"], (match_id, kinds)
        at = dict(steps)
        assert row.pull_at <= at["pull"] < row.stream_start
        assert at["play-start"] >= row.play_at and at["play-end"] <= row.stream_start
        assert at["deliver"] >= row.deliver_at
    table = standings(ledger.rows(), ["alpha", "bravo", "charlie"])
    assert sum(s.played for s in table) == 6
    alpha = next(s for s in table if s.team == "alpha")
    assert alpha.goals_for == 2 * goals("alpha")
    assert [s.points for s in table] == sorted((s.points for s in table), reverse=True)


def test_knockout_winners_advance(tmp_path: Path) -> None:
    path = write_schedule(
        tmp_path,
        COMPRESSED
        + "fixtures:\n  knockout: {seeds: [alpha, bravo, charlie, delta], first_stream: '+4s',"
        " interval_s: 1.0, stream_length_s: 0.3}\n",
    )
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    rows = {r.id: r for r in Ledger(state).rows()}
    final = rows["ko-r2-1"]
    assert final.state is ScheduledMatchState.DELIVERED, final
    semi_winners = {rows[m].result["winner_team"] for m in ("ko-r1-1", "ko-r1-2")}  # type: ignore[index]
    assert {final.red, final.blue} == semi_winners


def test_missed_match_is_marked_with_a_reason(tmp_path: Path) -> None:
    path = write_schedule(
        tmp_path,
        COMPRESSED + "matches:\n  - {id: late, red: alpha, blue: bravo, stream_start: '+0.5s'}\n",
    )
    state = tmp_path / "state.sqlite"
    from tournament import init_state

    init_state(path, state, services=FAKE)
    time.sleep(0.7)  # the scheduler was down past the stream start
    run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1)
    row = Ledger(state).row("late")
    assert row.state is ScheduledMatchState.MISSED and "window" in row.note
    assert not [e for e in services_log(path) if e[0].startswith("play")]


def test_cancel_and_status_cli(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    from hlvs.cli import main
    from tournament import init_state

    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+2h'}\n"
    )
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    assert main(["schedule", "cancel", "m1", "--state", str(state)]) == 0
    assert main(["schedule", "cancel", "m1", "--state", str(state)]) == 1
    assert main(["schedule", "status", "--state", str(state), "--json"]) == 0
    out = capsys.readouterr().out
    status = json.loads(out[out.index("[") :])
    assert status[0]["state"] == "CANCELLED"


def test_sigkill_mid_tournament_then_restart_plays_every_match_once(tmp_path: Path) -> None:
    path = write_schedule(
        tmp_path,
        # Long windows (pull 8 s before each stream) so that a slow restart on a loaded machine
        # still finds every match playable: the test is about exactly-once, not about misses.
        COMPRESSED.replace("pull_lead_round_robin_s: 3.0", "pull_lead_round_robin_s: 8.0")
        + "fixtures:\n  round_robin: {teams: [alpha, bravo, charlie, delta], first_stream: '+9s',"
        " interval_s: 1.5, stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    cmd = [
        sys.executable,
        "-m",
        "hlvs.cli",
        "schedule",
        "run",
        str(path),
        "--state",
        str(state),
        "--exit-when-done",
        "--services",
        FAKE,
    ]
    env = {**os.environ, "HLVS_FAKE_PLAY_S": "1.2"}
    first = subprocess.Popen(cmd, env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.monotonic() + 60
    playing = None
    while time.monotonic() < deadline:  # kill it while a match after the first is being played
        log = services_log(path)
        started = [m for w, m, _ in log if w == "play-start"]
        ended = {m for w, m, _ in log if w == "play-end"}
        if ended and started and started[-1] not in ended:
            playing = started[-1]
            break
        time.sleep(0.02)
    else:
        first.kill()
        pytest.fail("the second match never started")
    first.send_signal(signal.SIGKILL)
    first.wait()
    assert playing is not None
    assert Ledger(state).row(playing).state is ScheduledMatchState.PLAYING
    second = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=120)
    assert second.returncode == 0, second.stderr
    rows = Ledger(state).rows()
    assert len(rows) == 6
    log = services_log(path)
    for row in rows:
        ends = [m for w, m, _ in log if w == "play-end" and m == row.id]
        assert row.state is ScheduledMatchState.DELIVERED, row
        assert len(ends) == 1, (row.id, ends)
    assert Ledger(state).row(playing).state is ScheduledMatchState.DELIVERED
    history = [h for h in Ledger(state).history(playing) if "interrupted" in h[4]]
    assert history, "the interrupted match was not recorded as such"
    assert sum(1 for w, *_ in log if w == "deliver") == sum(
        1 for r in rows if r.state is ScheduledMatchState.DELIVERED
    )


def test_state_file_of_another_schedule_is_refused(tmp_path: Path) -> None:
    from orchestrator.errors import ScheduleError
    from tournament import init_state

    a = write_schedule(tmp_path, "matches: []\n")
    other = tmp_path / "b"
    other.mkdir()
    b = write_schedule(other, "matches: []\n")
    state = tmp_path / "state.sqlite"
    init_state(a, state)
    with pytest.raises(ScheduleError, match="belongs to the schedule"):
        init_state(b, state)


def test_reference_time_is_fixed_at_first_run(tmp_path: Path) -> None:
    from tournament import init_state

    path = write_schedule(
        tmp_path, "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+1h'}\n"
    )
    state = tmp_path / "state.sqlite"
    _, ledger = init_state(path, state, now=datetime(2030, 1, 1, tzinfo=UTC))
    first = ledger.row("m1").stream_start
    _, ledger = init_state(path, state, now=datetime(2031, 1, 1, tzinfo=UTC))
    assert ledger.row("m1").stream_start == first == datetime(2030, 1, 1, 1, tzinfo=UTC)


def test_sigterm_stops_a_playing_match_within_the_grace_then_restart_replays_it(
    tmp_path: Path,
) -> None:
    """A supervisor (systemd, Slurm) stops the scheduler with SIGTERM: the playing match is
    asked to stop at once, the scheduler exits within the grace period, the match is marked
    interrupted and played again (to its end, once) at the next start."""
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("pull_lead_round_robin_s: 3.0", "pull_lead_round_robin_s: 14.0")
        + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+15s',"
        " stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    cmd = [sys.executable, "-m", "hlvs.cli", "schedule", "run", str(path), "--state",
           str(state), "--exit-when-done", "--services", FAKE, "--stop-grace", "5"]
    first = subprocess.Popen(cmd, env={**os.environ, "HLVS_FAKE_PLAY_S": "120"},
                             stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 60
    while not any(w == "play-start" for w, _, _ in services_log(path)):
        if time.monotonic() > deadline or first.poll() is not None:
            first.kill()
            pytest.fail("the match never started")
        time.sleep(0.05)
    first.send_signal(signal.SIGTERM)
    asked = time.monotonic()
    try:
        first.wait(timeout=20)
    except subprocess.TimeoutExpired:
        first.kill()
        first.wait()
        pytest.fail("the scheduler was still running 20 s after SIGTERM")
    assert time.monotonic() - asked < 20 and first.returncode == 0
    assert [w for w, _, _ in services_log(path)] == ["pull", "play-start", "play-stopped"]
    row = Ledger(state).row("m1")
    assert row.state is ScheduledMatchState.PLAYING
    assert row.note.startswith("interrupted by the scheduler's stop")
    second = subprocess.run(cmd, env={**os.environ, "HLVS_FAKE_PLAY_S": "0.3"},
                            capture_output=True, text=True, timeout=120)
    assert second.returncode == 0, second.stderr
    assert Ledger(state).row("m1").state is ScheduledMatchState.DELIVERED
    assert [w for w, _, _ in services_log(path)].count("play-end") == 1
    notes = [note for *_, note in Ledger(state).history("m1")]
    assert any(n.startswith("interrupted by the scheduler's stop") for n in notes)
    assert "PLAYING interrupted by a restart" in notes


def test_two_tournaments_on_one_host_never_meet_on_a_match_id(tmp_path: Path) -> None:
    """Both have an ``rr-1``: their game.json (containers, Slurm jobs), log sets and the folders
    a team receives carry the tournament's name too."""
    from orchestrator.config.schedule import game_document

    ids = []
    for name in ("Spring Cup 2026", "Autumn Cup 2026"):
        folder = tmp_path / name.split()[0]
        folder.mkdir()
        path = write_schedule(folder, "fixtures:\n  round_robin: {teams: [alpha, bravo],"
                              " first_stream: '+1h'}\n")
        path.write_text(path.read_text().replace("name: test cup", f"name: {name}"))
        schedule = load_schedule(path)
        match = schedule.match("rr-1")
        game = game_document(schedule, match, schedule.team("alpha"), schedule.team("bravo"))
        ids.append(game["match_id"])
        assert schedule.league_match_id("rr-1") == game["match_id"]
    assert ids == ["spring-cup-2026-rr-1", "autumn-cup-2026-rr-1"]
    long = load_schedule(path)
    assert len(long.league_match_id("x" * 60)) <= 64


def test_two_schedules_in_one_folder_keep_their_match_folders_apart(tmp_path: Path) -> None:
    """Without ``output_dir``, match folders and log stores are under ``tournament/<name>``:
    two schedule files side by side never share ``tournament/rr-1``."""
    schedules = []
    for name, file in (("Spring Cup", "spring.yaml"), ("Autumn Cup", "autumn.yaml")):
        path = write_schedule(tmp_path, "fixtures:\n  round_robin: {teams: [alpha, bravo],"
                              " first_stream: '+1h'}\n")
        text = path.read_text().replace("name: test cup\noutput_dir: out\n", f"name: {name}\n")
        (tmp_path / file).write_text(text)
        schedules.append(load_schedule(tmp_path / file))
    spring, autumn = schedules
    assert spring.output_dir == (tmp_path / "tournament" / "spring-cup").resolve()
    assert autumn.output_dir == (tmp_path / "tournament" / "autumn-cup").resolve()
    assert spring.log_store != autumn.log_store


def test_a_friendly_match_plays_a_normal_game_and_counts_nowhere(tmp_path: Path) -> None:
    from orchestrator.config.schedule import game_document

    path = write_schedule(
        tmp_path,
        COMPRESSED + "matches:\n  - {id: f1, kind: friendly, red: alpha, blue: bravo,"
        " stream_start: '+3.5s', stream_length_s: 0.2}\n"
        "  - {id: m1, red: charlie, blue: delta, stream_start: '+3.8s', stream_length_s: 0.2}\n")
    schedule = load_schedule(path)
    friendly = schedule.match("f1")
    assert friendly.kind == "friendly"
    assert game_document(schedule, friendly, schedule.team("alpha"),
                         schedule.team("bravo"))["type"] == "NORMAL"
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    rows = Ledger(state).rows()
    assert {r.id: r.state for r in rows} == {"f1": ScheduledMatchState.DELIVERED,
                                             "m1": ScheduledMatchState.DELIVERED}
    table = {s.team: s.played for s in standings(rows, TEAMS)}
    assert table == {"alpha": 0, "bravo": 0, "charlie": 1, "delta": 1}
