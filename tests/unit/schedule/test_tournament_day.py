"""What a tournament operator relies on: truthful log states, shoot-outs in knockouts,
tie-breaks, one folder per attempt, status lines."""

from __future__ import annotations

import json
from collections.abc import Iterator
from datetime import UTC, datetime
from pathlib import Path

import pytest

from orchestrator.delivery.store import PendingSet, create_set, remove_set
from orchestrator.delivery.store import list_sets as pending_sets
from tests.unit.schedule import fake_services
from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, services_log, write_schedule
from tournament import Ledger, ScheduledMatchState, run_schedule, standings
from tournament.overview import status_lines
from tournament.services import keep_earlier_attempt
from tournament.state import MatchRow

S = ScheduledMatchState


def queue_set(store: Path, match_id: str, team: str) -> PendingSet:
    """A team's log set waiting in the store (the fake services deliver nothing), under the
    match's league id (the tournament's name, then its id)."""
    match_id = f"test-cup-{match_id}"
    source = store.parent / f"{match_id}-{team}.log"
    source.parent.mkdir(parents=True, exist_ok=True)
    source.write_text("log\n")
    return create_set(store, match_id=match_id, team=team, kind="team", credentials=None,
                      sources=[(source, "robot.log")], move=False)


@pytest.fixture
def fake() -> Iterator[None]:
    yield
    fake_services.DEAD_TEAMS.clear()
    fake_services.DRAWN.clear()


def test_failed_delivery_is_never_shown_delivered(tmp_path: Path, fake: None) -> None:
    fake_services.DEAD_TEAMS.add("bravo")
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("retry_s: 0.2", "retry_s: 0.2, delivery_attempts: 2")
        + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+3.5s',"
        " stream_length_s: 0.2}\n"
        "  - {id: m2, red: charlie, blue: delta, stream_start: '+3.8s', stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    ledger = Ledger(state)
    m1, m2 = ledger.row("m1"), ledger.row("m2")
    assert m2.state is S.DELIVERED and {e.state for e in m2.logs} == {"delivered"}
    assert m1.state is S.LOGS_FAILED and m1.state.played
    logs = {e.team: e for e in m1.logs}
    assert logs["alpha"].state == "delivered" and logs["alpha"].attempts == 1
    assert logs["bravo"].state == "failed" and logs["bravo"].attempts == 2
    assert "unreachable: connection refused" in logs["bravo"].cause
    history = [(to, note) for _, _, _, to, note in ledger.history("m1")]
    assert ("LOGS_PENDING", "logs: alpha delivered; bravo retrying "
            "(unreachable: connection refused)") in history
    assert not any(to == "DELIVERED" for to, _ in history)
    assert [w for w, mid, _ in services_log(path) if mid == "m1"][-2:] == ["deliver",
                                                                           "redeliver"]
    pending = queue_set(tmp_path / "out" / "log-store", "m1", "bravo")  # as a real one stays
    lines = "\n".join(status_lines(ledger))
    assert "m1" in lines and "LOGS_FAILED" in lines and "played" in lines
    assert "bravo failed after 2 attempts (unreachable: connection refused)" in lines
    assert "alpha delivered" in lines
    remove_set(pending)  # delivered by 'hlvs logs deliver' (or pruned): the status says so
    lines = "\n".join(status_lines(ledger))
    assert "bravo gone after 2 attempts (no longer in the log store" in lines
    as_dict = m1.as_dict()
    assert as_dict["played"] is True and as_dict["logs_delivered"] is False


def test_knockout_draw_goes_to_a_shootout_and_the_bracket_advances(
    tmp_path: Path, fake: None
) -> None:
    fake_services.DRAWN.add("ko-r1-1")
    path = write_schedule(
        tmp_path,
        COMPRESSED
        + "fixtures:\n  knockout: {seeds: [alpha, bravo, charlie, delta], first_stream: '+4s',"
        " interval_s: 1.0, stream_length_s: 0.3}\n",
    )
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    rows = {r.id: r for r in Ledger(state).rows()}
    semi = rows["ko-r1-1"].result
    assert semi is not None and semi["score"] == {"red": 1, "blue": 1}
    assert semi["winner"] in ("red", "blue") and sorted(semi["shootout"].values()) == [2, 3]
    assert [w for w, m, _ in services_log(path) if m == "ko-r1-1"][:4] == [
        "pull", "play-start", "play-end", "shootout"]
    final = rows["ko-r2-1"]
    assert final.state is S.DELIVERED
    assert semi["winner_team"] in (final.red, final.blue)
    assert "(shoot-out " in "\n".join(status_lines(Ledger(state)))


def _row(match_id: str, red: str, blue: str, score: tuple[int, int]) -> MatchRow:
    now = datetime.now(UTC)
    return MatchRow(
        id=match_id, state=S.DELIVERED, kind="round_robin", red=red, blue=blue, pull_at=now,
        play_at=now, stream_start=now, stream_end=now, deliver_at=now, attempts=1, note="",
        result={"red_team": red, "blue_team": blue,
                "score": {"red": score[0], "blue": score[1]}},
        updated_at=now,
    )


def test_ties_are_broken_head_to_head_then_by_a_documented_rule() -> None:
    rows = [
        _row("1", "alpha", "bravo", (0, 1)),  # bravo beat alpha
        _row("2", "alpha", "charlie", (5, 0)),  # alpha: better goal difference overall
        _row("3", "bravo", "charlie", (0, 1)),
        _row("4", "delta", "echo", (1, 1)),
    ]
    table = standings(rows, ["alpha", "bravo", "charlie", "delta", "echo"], seed="cup")
    order = [s.team for s in table]
    # alpha, bravo and charlie have 3 points each; in their mini-table each won once:
    # head-to-head goal difference decides (alpha +4, bravo 0, charlie -4)
    assert order[:3] == ["alpha", "bravo", "charlie"]
    assert table[0].decided_by == "head-to-head"
    # delta and echo: level on everything, a drawing of lots fixed by the tournament's name
    tail = [s for s in table if s.team in ("delta", "echo")]
    assert tail[0].decided_by == "drawing of lots" and tail[1].decided_by == ""
    again = standings(rows, ["echo", "delta", "charlie", "bravo", "alpha"], seed="cup")
    assert [s.team for s in again] == order


def test_head_to_head_before_goal_difference() -> None:
    rows = [
        _row("1", "alpha", "bravo", (0, 1)),  # bravo beat alpha head-to-head
        _row("2", "alpha", "charlie", (9, 0)),
        _row("3", "bravo", "charlie", (0, 0)),
        _row("4", "charlie", "bravo", (1, 0)),
        _row("5", "alpha", "charlie", (0, 0)),
    ]
    table = standings(rows, ["alpha", "bravo", "charlie"])
    # charlie 5 points; bravo and alpha 4 each, alpha with the better goal difference (+8, 0)
    assert [(s.team, s.points) for s in table] == [("charlie", 5), ("bravo", 4), ("alpha", 4)]
    assert table[1].decided_by == "head-to-head" and table[0].decided_by == ""


def test_every_attempt_keeps_its_folder(tmp_path: Path) -> None:
    out = tmp_path / "match"
    assert keep_earlier_attempt(out) is None
    out.mkdir()
    (out / "report.json").write_text("first")
    (out / "teams" / "red").mkdir(parents=True)
    assert keep_earlier_attempt(out) == out / "attempt-1"
    (out / "report.json").write_text("second")
    assert keep_earlier_attempt(out) == out / "attempt-2"
    assert (out / "attempt-1" / "report.json").read_text() == "first"
    assert (out / "attempt-1" / "teams" / "red").is_dir()
    assert (out / "attempt-2" / "report.json").read_text() == "second"
    assert sorted(p.name for p in out.iterdir()) == ["attempt-1", "attempt-2"]


def test_overview_and_status_watch(
    tmp_path: Path, fake: None, monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    from hlvs.cli import main
    from tournament import init_state
    from tournament.overview import tournament_overview

    path = write_schedule(
        tmp_path,
        "fixtures:\n  knockout: {seeds: [alpha, bravo, charlie, delta], first_stream: '+2h'}\n"
        "matches:\n  - {id: third, kind: knockout, red: {loser_of: ko-r1-1},"
        " blue: {loser_of: ko-r1-2}, stream_start: '+5h'}\n")
    state = tmp_path / "state.sqlite"
    init_state(path, state)
    ledger = Ledger(state)
    assert ledger.transition("ko-r1-1", (S.PLANNED,), S.PLAYING)
    live = {"state": "PLAYING", "half": 1, "secs_remaining": 75, "score": {"red": 1, "blue": 0}}
    view = tournament_overview(ledger, snapshot=lambda folder: live)
    assert view["name"] == "test cup" and view["warnings"] == []
    assert view["bracket"] == [["ko-r1-1", "ko-r1-2"], ["third", "ko-r2-1"]]
    playing = view["matches"][0]
    assert playing["id"] == "ko-r1-1" and playing["clock_text"] == "1-0 PLAYING 1st half 01:15"
    assert playing["watch"] == {}  # no telemetry spec in its folder: no live link
    assert [m["played"] for m in view["matches"]] == [False] * 4

    sleeps: list[float] = []

    def sleep(seconds: float) -> None:
        sleeps.append(seconds)
        if len(sleeps) == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr("time.sleep", sleep)
    assert main(["schedule", "status", "--state", str(state), "--watch", "--every", "0.5"]) == 0
    out = capsys.readouterr().out
    assert sleeps == [0.5, 0.5] and out.count("(every 0.5 s, Ctrl-C to stop)") == 2
    assert out.count("ko-r1-1      PLAYING") == 2


def test_the_referees_shootout_is_read_from_the_public_sim_result(tmp_path: Path) -> None:
    from tournament.services import shootout_goals

    path = tmp_path / "sim_result.json"
    assert shootout_goals(path) is None  # no file
    path.write_text(json.dumps({"score": {"red": 1, "blue": 1}}))
    assert shootout_goals(path) is None  # no shoot-out
    path.write_text(json.dumps({"shootout": {"red": {"kicks": 5, "scored": 4},
                                             "blue": {"kicks": 5, "scored": 3}}}))
    assert shootout_goals(path) == {"red": 4, "blue": 3}


def test_a_knockout_decided_on_penalties_keeps_the_match_goals_apart(
    tmp_path: Path, fake: None
) -> None:
    """The referee's shoot-out (a KNOCKOUT game drawn after extra time): the GameController's
    score counts the kicks, the tournament shows the match's goals and the shoot-out's apart."""
    from tournament.overview import tournament_overview

    fake_services.DRAWN.add("ko-r1-1")
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("pull_lead_knockout_s: 3.5", "pull_lead_knockout_s: 10.0")
        + "fixtures:\n  knockout: {seeds: [alpha, bravo], first_stream: '+10.5s',"
        " stream_length_s: 0.3}\n",
    )
    state = tmp_path / "state.sqlite"
    services = "tests.unit.schedule.fake_services:MatchFolderServices"
    assert run_schedule(path, state, services=services, exit_when_done=True, poll_s=0.1) == 0
    results = json.loads((tmp_path / "out" / "ko-r1-1" / "match" / "results.json").read_text())
    assert results["score"] == {"red": 0, "blue": 0}
    assert results["shootout"] == {"red": 3, "blue": 2} and results["winner"] == "red"
    row = Ledger(state).row("ko-r1-1")
    assert row.result is not None and row.result["score"] == {"red": 0, "blue": 0}
    assert row.result["winner_team"] == "alpha"
    assert "ko-r1-1" in "".join(status_lines(Ledger(state)))
    assert "0-0 (shoot-out 3-2)" in "\n".join(status_lines(Ledger(state)))
    page = tournament_overview(Ledger(state))
    assert [m["score_text"] for m in page["matches"]] == ["0-0 (shoot-out 3-2)"]
    assert page["bracket"] == [["ko-r1-1"]]
    assert [w for w, m, _ in services_log(path) if m == "ko-r1-1"].count("shootout") == 0


def test_a_results_file_written_before_the_shootout_was_kept_apart_reads_right(
    tmp_path: Path,
) -> None:
    """A match folder of an earlier version: results.json's score counts the shoot-out's
    goals and has no ``shootout``; the public sim_result.json says how many they were."""
    from contracts import MatchReport
    from tournament.services import read_outcome

    (tmp_path / "public").mkdir()
    (tmp_path / "public" / "sim_result.json").write_text(json.dumps(
        {"shootout": {"red": {"kicks": 5, "scored": 2}, "blue": {"kicks": 5, "scored": 4}}}))
    results = {"version": 1, "match_id": "m", "status": "success", "failure": None, "seed": 1,
               "score": {"red": 3, "blue": 5}, "winner": "blue",
               "limits": {"cpus": 1.0, "memory_gb": 1.0, "pids": 1, "log_folder_gb": 1.0,
                          "team_api_mb_s": 1.0, "team_comm_mb_s": 1.0, "grace_period_s": 1.0,
                          "allow_internet": False, "host_controls": None}}
    (tmp_path / "results.json").write_text(json.dumps(results))
    MatchReport.of(None).write(tmp_path / "report.json")
    outcome = read_outcome(tmp_path)
    assert (outcome.score_red, outcome.score_blue, outcome.shootout, outcome.winner) == (
        1, 1, {"red": 2, "blue": 4}, "blue")


def test_a_match_waiting_for_the_simulator_slot_does_not_flood_the_log(
    tmp_path: Path, caplog: pytest.LogCaptureFixture
) -> None:
    """Two matches due at once, one simulator slot: the second waits in the executor's queue;
    the runner must not add its job again at every pass (APScheduler would log "skipped:
    maximum number of running instances reached" each time), and such a line is not repeated
    for a job within a minute."""
    import logging

    before = fake_services.PLAY_SECONDS
    fake_services.PLAY_SECONDS = 2.0
    path = write_schedule(
        tmp_path,
        COMPRESSED + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+6s',"
        " stream_length_s: 0.2}\n  - {id: m2, red: charlie, blue: delta,"
        " stream_start: '+6s', stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    try:
        with caplog.at_level(logging.WARNING, logger="apscheduler"):
            assert run_schedule(path, state, services=FAKE, exit_when_done=True,
                                poll_s=0.05) == 0
    finally:
        fake_services.PLAY_SECONDS = before
    assert {r.state for r in Ledger(state).rows()} == {S.DELIVERED}
    starts = [(m, at) for w, m, at in services_log(path) if w == "play-start"]
    assert len(starts) == 2 and (starts[1][1] - starts[0][1]).total_seconds() >= 1.9
    flood = [str(r.args[0]).split(" (")[0] for r in caplog.records  # type: ignore[index]
             if "maximum number of running instances" in r.msg]
    assert len(flood) == len(set(flood)), flood  # a job is queued, never added again and again


def test_logs_delivered_by_hand_after_a_fix_clear_logs_failed(tmp_path: Path, fake: None) -> None:
    """A team's target was down for every attempt (LOGS_FAILED); the operator fixes it and
    runs 'hlvs logs deliver': the set is delivered, its receipt stays in the store, and the
    match becomes DELIVERED, its note and its logs saying the same."""
    from orchestrator.delivery import FakeUploader, RetryPolicy, deliver_pending
    from tests.unit.schedule.test_schedule import write_credentials

    fake_services.DEAD_TEAMS.add("bravo")
    path = write_schedule(
        tmp_path,
        COMPRESSED.replace("retry_s: 0.2", "retry_s: 0.2, delivery_attempts: 1")
        + "matches:\n  - {id: m1, red: alpha, blue: bravo, stream_start: '+3.5s',"
        " stream_length_s: 0.2}\n  - {id: m2, red: charlie, blue: bravo,"
        " stream_start: '+3.9s', stream_length_s: 0.2}\n",
    )
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    ledger = Ledger(state)
    assert ledger.row("m1").state is S.LOGS_FAILED and ledger.row("m2").state is S.LOGS_FAILED
    store = tmp_path / "out" / "log-store"
    credentials = write_credentials(tmp_path / "bravo-logs.json")
    source = tmp_path / "robot.log"
    source.write_text("log\n")
    for match_id in ("m1", "m2"):  # as the real services leave a failed set in the store
        create_set(store, match_id=f"test-cup-{match_id}", team="bravo", kind="team",
                   credentials=credentials,
                   sources=[(source, "robot.log")], move=False)
    assert "m1" in "\n".join(status_lines(ledger))
    assert ledger.row("m1").state is S.LOGS_FAILED  # still waiting in the store
    uploader = FakeUploader()
    [outcome] = deliver_pending(store, match_id="test-cup-m1", opener=lambda creds, team: uploader,
                                retry=RetryPolicy(attempts=1, initial_delay_s=0.0, factor=1.0,
                                                  max_delay_s=0.0))
    assert outcome.delivered
    for pending in [s for s in pending_sets(store) if s.match_id == "test-cup-m2"]:
        remove_set(pending)  # m2's set was pruned, never delivered
    lines = "\n".join(status_lines(ledger))
    m1, m2 = ledger.row("m1"), ledger.row("m2")
    assert m1.state is S.DELIVERED, m1
    assert {e.team: e.state for e in m1.logs} == {"alpha": "delivered", "bravo": "delivered"}
    assert m1.note == "logs: alpha delivered; bravo delivered" and "m1" in lines
    assert m2.state is S.LOGS_FAILED and {e.team: e.state for e in m2.logs}["bravo"] == "gone"
    assert "never delivered (pruned)" in m2.note
    assert [to for _, _, _, to, _ in ledger.history("m1")][-1] == "DELIVERED"


def test_export_gives_scores_shootouts_and_standings_as_json_and_csv(
    tmp_path: Path, fake: None, capsys: pytest.CaptureFixture[str]
) -> None:
    import csv
    import io

    from hlvs.cli import main

    fake_services.DRAWN.add("ko-r1-1")
    path = write_schedule(
        tmp_path,
        # long windows: the test is about the export, not about misses on a loaded machine
        COMPRESSED.replace("pull_lead_knockout_s: 3.5", "pull_lead_knockout_s: 10.0")
        .replace("pull_lead_round_robin_s: 3.0", "pull_lead_round_robin_s: 10.0")
        + "matches:\n  - {id: m1, red: charlie, blue: delta, stream_start: '+10.2s',"
        " stream_length_s: 0.2}\n"
        "fixtures:\n  knockout: {seeds: [alpha, bravo], first_stream: '+10.5s',"
        " stream_length_s: 0.3}\n",
    )
    state = tmp_path / "state.sqlite"
    services = "tests.unit.schedule.fake_services:MatchFolderServices"
    assert run_schedule(path, state, services=services, exit_when_done=True, poll_s=0.1) == 0
    capsys.readouterr()
    assert main(["schedule", "export", "--state", str(state)]) == 0
    document = json.loads(capsys.readouterr().out)
    assert document["name"] == "test cup" and document["bracket"] == [["ko-r1-1"]]
    final = next(m for m in document["matches"] if m["id"] == "ko-r1-1")
    assert (final["red_goals"], final["blue_goals"], final["shootout_red"],
            final["shootout_blue"], final["winner"], final["score"]) == (
        0, 0, 3, 2, "alpha", "0-0 (shoot-out 3-2)")
    m1 = next(m for m in document["matches"] if m["id"] == "m1")
    assert (m1["red_goals"], m1["blue_goals"]) == (fake_services.goals("charlie"),
                                                   fake_services.goals("delta") + 4)
    assert m1["shootout_red"] is None and m1["winner"] == "delta"
    table = {s["team"]: s for s in document["standings"]}
    assert table["delta"]["points"] == 3 and table["delta"]["rank"] == 1
    assert table["alpha"]["played"] == 0  # a knockout match is not in the table
    out = tmp_path / "matches.csv"
    assert main(["schedule", "export", "--state", str(state), "--format", "csv", "--out",
                 str(out)]) == 0
    rows = {r["id"]: r for r in csv.DictReader(io.StringIO(out.read_text()))}
    assert rows["ko-r1-1"]["score"] == "0-0 (shoot-out 3-2)"
    assert rows["ko-r1-1"]["shootout_red"] == "3" and rows["m1"]["shootout_red"] == ""
    assert rows["ko-r1-1"]["played"] == "true"
    assert capsys.readouterr().out == f"{out}: 2 matches\n"
    assert main(["schedule", "export", "--state", str(state), "--format", "csv", "--table",
                 "standings"]) == 0
    standings_csv = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    assert [r["team"] for r in standings_csv][0] == "delta" and len(standings_csv) == 4
    assert main(["schedule", "export", "--state", str(tmp_path / "none.sqlite")]) == 2


def test_the_max_instances_line_is_logged_once_a_minute_per_job() -> None:
    import logging
    from types import SimpleNamespace

    from tournament.runner import _OncePerMinute

    quiet = _OncePerMinute()
    message = ('Execution of job "%s" skipped: maximum number of running instances reached '
               "(%d)")

    def record(job_id: str) -> logging.LogRecord:
        job = SimpleNamespace(id=job_id)  # its text changes with its next run time
        return logging.LogRecord("apscheduler.scheduler", logging.WARNING, "", 0, message,
                                 (job, 1), None)

    assert [quiet.filter(record(j)) for j in ("play:m2", "play:m2", "play:m3", "play:m2")] == [
        True, False, True, False]
    other = logging.LogRecord("apscheduler.scheduler", logging.WARNING, "", 0, "other", (), None)
    assert quiet.filter(other) and quiet.filter(other)
