"""The ladder over the real app (SQLite, fake match pool writing real results files): four teams
that accept friendlies are paired by the ladder in free slots, their matches are rated with
OpenSkill once each, a match that did not play is not rated, ladder matches are not charged, and
the table is ordered by rating."""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import httpx
from sqlalchemy import select

from cluster.fake import FakePool, fake_results
from contracts import files
from contracts.match_results import MatchReport
from contracts.sim_result import PlayRecord
from service.db import Submission, SubmissionState, make_engine, session_factory, transaction
from service.db.ladder import RatedMatch
from service.ratings import outcome_of, outcome_of_file
from service.results import MatchSummary
from tests.integration.service.harness import Served
from tests.unit.service.conftest import wait_for_status
from tests.unit.service.test_submissions import setup_team

STRENGTH = {"Anchors": 4, "Bravo": 3, "Comets": 2, "Dingos": 1}


def _play(goals: dict[str, int], *, played: bool = True) -> PlayRecord | None:
    if not played:
        return None
    zero = {"red": 0, "blue": 0}
    return PlayRecord(halves_playing=(1, 2), both_halves_playing=True, playing_s=80.0,
                      kicks=dict(goals), shots=dict(goals), goals=dict(goals),
                      own_goals=zero, falls=zero)


def finish(pool: FakePool, handle: str, red_goals: int, blue_goals: int, *,
           played: bool = True) -> None:
    """End a running fake match as a real one ends: results.json, then report.json."""
    out = pool.results_dir(handle)
    (out / "public").mkdir(parents=True, exist_ok=True)
    goals = {"red": red_goals, "blue": blue_goals}
    winner = "red" if red_goals > blue_goals else "blue" if blue_goals > red_goals else "draw"
    results = replace(fake_results(Path(handle).name, None), score=goals, winner=winner,
                      play=_play(goals, played=played))
    results.write(out / files.RESULTS)
    MatchReport.from_dict({"status": "success"}, source="test").write(out / files.REPORT)
    (Path(handle) / "running").unlink()


def running_match(served: Served, timeout_s: float = 10.0) -> tuple[str, str, str, str]:
    """(submission id, pool handle, team, opponent) of the match the ladder started."""
    from service.db import Team

    engine = make_engine(served.settings.db_url)
    deadline = time.monotonic() + timeout_s
    try:
        while True:
            with transaction(session_factory(engine)) as session:
                found = session.execute(select(Submission, Team.name).join(
                    Team, Team.id == Submission.team_id).where(
                    Submission.state == SubmissionState.RUNNING.value)).first()
                if found is not None:
                    row, team = found
                    assert row.pool_handle is not None
                    return row.id, row.pool_handle, team, row.opponent
            assert time.monotonic() < deadline, "the ladder started no match"
            time.sleep(0.05)
    finally:
        engine.dispose()


def rated_count(served: Served) -> int:
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        count = len(list(session.scalars(select(RatedMatch))))
    engine.dispose()
    return count


def wait_rated(served: Served, count: int, timeout_s: float = 10.0) -> None:
    deadline = time.monotonic() + timeout_s
    while rated_count(served) < count:
        assert time.monotonic() < deadline, f"fewer than {count} matches recorded"
        time.sleep(0.05)


def test_ladder_pairs_rates_and_orders_four_teams(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    served = start(ladder_every_s=0.01)
    secrets = {name: token(name, accepts_friendlies=True) for name in STRENGTH}
    clients: dict[str, httpx.Client] = {n: setup_team(served, s, n) for n, s in secrets.items()}
    first = clients["Anchors"].get("/v1/ladder").json()
    assert [t["rating"] for t in first["teams"]] == [0.0] * 4
    assert first["matches_rated"] == 0 and first["ladder_every_s"] == 0.01

    pairs: list[frozenset[str]] = []
    # the first ladder match does not play: recorded once, not rated
    sid, handle, team, opponent = running_match(served)
    status = clients[team].get(f"/v1/submissions/{sid}").json()
    assert status["charged"] is False and status["opponent"] == opponent
    finish(pool, handle, 0, 0, played=False)
    wait_rated(served, 1)
    assert clients[team].get("/v1/ladder").json()["matches_rated"] == 0

    for n in range(8):
        sid, handle, team, opponent = running_match(served)
        assert team != opponent and {team, opponent} <= set(STRENGTH)
        pairs.append(frozenset((team, opponent)))
        stronger_red = STRENGTH[team] > STRENGTH[opponent]
        finish(pool, handle, 2 if stronger_red else 0, 0 if stronger_red else 1)
        wait_rated(served, n + 2)
    assert len(set(pairs)) >= 4  # the ladder moves teams around, not one pair again and again
    # every ladder match was free
    seen = []
    for http in clients.values():
        mine = http.get("/v1/submissions").json()
        seen += mine["items"] if isinstance(mine, dict) else mine
    assert len(seen) >= 9 and [s for s in seen if s["charged"]] == []

    table = clients["Dingos"].get("/v1/ladder").json()
    ratings = [t["rating"] for t in table["teams"]]
    assert table["matches_rated"] == 8
    assert ratings == sorted(ratings, reverse=True) and len(set(ratings)) == 4
    assert [t["team"] for t in table["teams"]] == list(STRENGTH)  # strongest first
    assert sum(t["played"] for t in table["teams"]) == 16
    top = table["teams"][0]
    assert top["won"] == top["played"] and top["lost"] == 0 and top["rating"] > 0
    assert table["teams"][-1]["won"] == 0

    detail = clients["Comets"].get("/v1/ladder/Anchors").json()
    assert detail["team"]["rank"] == 1 and len(detail["matches"]) == top["played"]
    assert len(detail["history"]) == top["played"] + 1
    points = [p["rating"] for p in detail["history"]]
    assert points == sorted(points) and points[0] == 0.0  # each win climbs
    newest = detail["matches"][0]
    assert newest["outcome"] == "won" and newest["rating_after"] == points[-1]
    assert newest["replay_url"] == f"/watch/replay/{newest['id']}"
    missing = clients["Comets"].get("/v1/ladder/Nobody")
    assert missing.status_code == 404 and "Nobody" in missing.json()["message"]


def test_ladder_off_waits_for_a_free_slot_and_survives_a_restart(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    served = start()  # ladder off: a team's friendly is still rated
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Alpha", "Beta")}
    clients = {n: setup_team(served, s, n) for n, s in secrets.items()}
    created = clients["Alpha"].post("/v1/submissions", json={"opponent": "Beta"})
    assert created.status_code == 201, created.text
    sid, handle, _, _ = running_match(served)
    assert clients["Alpha"].get(f"/v1/submissions/{sid}").json()["charged"] is True
    finish(pool, handle, 1, 1)
    wait_rated(served, 1)
    table = clients["Beta"].get("/v1/ladder").json()["teams"]
    assert [(t["drawn"], t["played"]) for t in table] == [(1, 1), (1, 1)]
    assert table[0]["sigma"] < 25 / 3 and table[0]["rating"] == table[1]["rating"]
    served.stop()
    served = start(ladder_every_s=3600.0)  # restarted: nothing counted twice
    http = served.client(secrets["Alpha"])
    ladder_id, handle, _, _ = running_match(served)  # the ladder's first fixture
    assert ladder_id != sid
    assert http.get("/v1/ladder").json()["matches_rated"] == 1
    # an hour between fixtures: after this one ends, none is scheduled however free the slot
    finish(pool, handle, 3, 0)
    wait_rated(served, 2)
    time.sleep(0.3)
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        assert len(list(session.scalars(select(Submission)))) == 2
    engine.dispose()
    assert http.get("/v1/ladder").json()["matches_rated"] == 2
    schema = http.get("/openapi.json").json()
    assert {"/v1/ladder", "/v1/ladder/{team}"} <= set(schema["paths"])
    assert {"LadderView", "TeamLadderView", "LadderMatch"} <= set(schema["components"]["schemas"])
    assert httpx.get(f"{served.url}/v1/ladder").status_code == 401  # signed-in readers only


def test_a_match_without_play_or_results_is_not_counted(tmp_path: Path) -> None:
    missing = outcome_of_file(tmp_path / "results.json")
    assert not missing.counted and "results.json" in (missing.note or "")
    unrecorded = outcome_of(None)
    assert not unrecorded.counted and "no result recorded" in (unrecorded.note or "")
    path = tmp_path / "played.json"
    results: Any = replace(fake_results("m", None), score={"red": 0, "blue": 2}, winner="blue",
                           play=_play({"red": 0, "blue": 2}))
    results.write(path)
    for played in (outcome_of_file(path), outcome_of(MatchSummary.of(results, {}))):
        assert played.counted and (played.red_goals, played.blue_goals, played.winner) == (
            0, 2, "blue")
    unplayed = outcome_of(MatchSummary.of(replace(results, play=None), {}))
    assert not unplayed.counted and "did not play" in (unplayed.note or "")


def test_official_matches_of_the_tournament_are_rated_once(
    start: Callable[..., Served], token: Callable[..., str], tmp_path: Path,
) -> None:
    from tests.unit.schedule.test_schedule import COMPRESSED, FAKE, write_schedule
    from tournament import Ledger, run_schedule, standings

    path = write_schedule(tmp_path, COMPRESSED + "fixtures:\n  round_robin: {teams: [alpha, "
                          "bravo, charlie], first_stream: '+4s', interval_s: 0.5, "
                          "stream_length_s: 0.3}\n")
    state = tmp_path / "state.sqlite"
    assert run_schedule(path, state, services=FAKE, exit_when_done=True, poll_s=0.1) == 0
    served = start(schedule_state=str(state))
    http = served.client(token("Observer"))  # a team that plays no friendly reads it too
    wait_rated(served, 3)
    table = http.get("/v1/ladder").json()
    expected = {s.team: s for s in standings(Ledger(state).rows(), ["alpha", "bravo", "charlie"])}
    assert table["matches_rated"] == 3
    assert {t["team"]: (t["won"], t["drawn"], t["lost"], t["goals_for"], t["goals_against"])
            for t in table["teams"]} == {
        name: (s.won, s.drawn, s.lost, s.goals_for, s.goals_against)
        for name, s in expected.items()}
    ratings = [t["rating"] for t in table["teams"]]
    assert ratings == sorted(ratings, reverse=True) and ratings[0] != ratings[-1]
    matches = http.get(f"/v1/ladder/{table['teams'][0]['team']}").json()["matches"]
    assert {m["source"] for m in matches} == {"official"} and len(matches) == 2
    assert all(m["replay_url"] is None for m in matches)
    time.sleep(0.3)  # further rounds of the ladder thread
    assert rated_count(served) == 3


def test_a_friendly_cancelled_after_kick_off_is_rated_as_the_askers_forfeit(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    """As found: the asking team, leading or not, cancels its running friendly after both
    halves played; it is rated all the same, as its forfeit (the opponent wins)."""
    served = start()
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Alpha", "Beta")}
    clients = {n: setup_team(served, s, n) for n, s in secrets.items()}
    sid = clients["Alpha"].post("/v1/submissions", json={"opponent": "Beta"}).json()["id"]
    running_match(served)
    assert clients["Alpha"].post(f"/v1/submissions/{sid}/cancel").status_code == 200
    # the fake pool stops it as a real one does: interrupted, with the play up to then (both
    # halves, red, the asker, ahead 1-0)
    ended = wait_for_status(clients["Alpha"], sid, lambda b: b["state"] == "cancelled")
    assert ended["state"] == "cancelled"
    wait_rated(served, 1)
    ladder = clients["Beta"].get("/v1/ladder").json()
    assert ladder["matches_rated"] == 1, ladder
    table = {t["team"]: t for t in ladder["teams"]}
    assert (table["Beta"]["won"], table["Alpha"]["lost"]) == (1, 1), table
    assert table["Beta"]["rating"] > table["Alpha"]["rating"]


def test_a_friendly_that_never_kicked_off_is_not_rated_and_a_failure_forfeits_its_side(
) -> None:
    from contracts import Failure, FailureClass
    from service.ratings import friendly_outcome

    def summary(results: Any) -> MatchSummary:
        return MatchSummary.of(results, {"red": "Alpha", "blue": "Beta"})

    before = replace(fake_results("m", Failure(failure_class=FailureClass.INTERRUPTED,
                                               cause="stop")), play=None)
    assert not friendly_outcome(summary(before), "cancelled", cancelled=True).counted
    assert not friendly_outcome(None, "failed", cancelled=False).counted
    failed = replace(fake_results("m", Failure(failure_class=FailureClass.TEAM_CRASH,
                                               cause="crash", team="red"), played=True),
                     score={"red": 3, "blue": 0})
    outcome = friendly_outcome(summary(failed), "failed", cancelled=False)
    assert outcome.counted and outcome.winner == "blue"
    league = replace(failed, failure=Failure(failure_class=FailureClass.INFRASTRUCTURE,
                                             cause="node lost"))
    outcome = friendly_outcome(summary(league), "failed", cancelled=False)
    assert outcome.counted and (outcome.red_goals, outcome.blue_goals, outcome.winner) == (
        3, 0, "red")


def test_both_sides_of_a_friendly_field_the_services_number_of_players(
    start: Callable[..., Served], token: Callable[..., str], pool: FakePool,
) -> None:
    """As found: each side brought its own team file's count (2 robots against 1). Both field
    the service's number (``test_players``), the lowest-numbered players of each file."""
    import json

    from tests.unit.service.conftest import team_doc

    served = start(test_players=2)
    secrets = {name: token(name, accepts_friendlies=True) for name in ("Alpha", "Beta")}
    docs = {}
    for name, count in (("Alpha", 3), ("Beta", 2)):
        doc = team_doc(name)
        first = doc["players"]["1"]
        doc["players"] = {str(n): dict(first) for n in range(count, 0, -1)}
        docs[name] = doc
        with served.client(secrets[name]) as http:
            stored = http.put("/v1/team/files/team_config", json=doc)
            assert stored.status_code == 201, stored.text
    with served.client(secrets["Alpha"]) as http:
        created = http.post("/v1/submissions", json={"opponent": "Beta"})
        assert created.status_code == 201, created.text
        sid, _, _, _ = running_match(served)
    match_dirs = list((served.settings.matches_dir).glob(f"{sid}-a1"))
    assert match_dirs, list(served.settings.matches_dir.iterdir())
    config = match_dirs[0] / "config"
    red = json.loads((config / "team_red.json").read_text())
    blue = json.loads((config / "team_blue.json").read_text())
    game = json.loads((config / "game.json").read_text())
    assert sorted(red["players"]) == sorted(blue["players"]) == ["1", "2"]
    assert len(game["red"]["ports"]) == len(game["blue"]["ports"]) == 2


def test_the_ladders_team_list_follows_teams_joining_and_leaving_at_the_same_count(
    start: Callable[..., Served], token: Callable[..., str],
) -> None:
    """As found: the table was cached by the number of teams on the ladder, so one team
    leaving as another joined (or a rename) left the old names on the table."""
    served = start()
    secrets = {"Alpha": token("Alpha", accepts_friendlies=True),
               "Beta": token("Beta", accepts_friendlies=True), "Gamma": token("Gamma")}
    http = {name: served.client(secret) for name, secret in secrets.items()}
    assert [t["team"] for t in http["Alpha"].get("/v1/ladder").json()["teams"]] == [
        "Alpha", "Beta"]
    assert http["Beta"].patch("/v1/team", json={"accepts_friendlies": False}).status_code == 200
    assert http["Gamma"].patch("/v1/team", json={"accepts_friendlies": True}).status_code == 200
    assert [t["team"] for t in http["Alpha"].get("/v1/ladder").json()["teams"]] == [
        "Alpha", "Gamma"]
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:  # an operator renames a team
        from service.db import Team
        team = session.scalar(select(Team).where(Team.name == "Gamma"))
        assert team is not None
        team.name = "Gamma United"
    engine.dispose()
    assert [t["team"] for t in http["Alpha"].get("/v1/ladder").json()["teams"]] == [
        "Alpha", "Gamma United"]
    assert http["Alpha"].get("/v1/ladder/Gamma").status_code == 404
