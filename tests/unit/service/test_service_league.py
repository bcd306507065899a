"""The league table (OpenSkill ratings replayed over played friendlies) and the ladder that
schedules friendlies between teams that accept them, with the fake pool (every match 1:0 for
the team that submitted it); each role's view of the queue and the matches."""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator
from datetime import UTC, datetime, timedelta
from typing import Any

import pytest

from service import Settings
from service.league import RatedMatch, table
from service.pool.fake import FakePool
from tests.integration.service.harness import Served, serve
from tests.unit.service.conftest import FakePreflight, team_doc

TEAMS = ("Ants", "Bees", "Cats", "Dogs")


def _match(n: int, red: str, blue: str, winner: str) -> RatedMatch:
    score = {"red": 1, "blue": 0} if winner == "red" else \
        {"red": 0, "blue": 1} if winner == "blue" else {"red": 0, "blue": 0}
    return RatedMatch(submission_id=f"sub_{n}", red=red, blue=blue, score=score, winner=winner,
                      finished_at=datetime(2026, 1, 1, tzinfo=UTC) + timedelta(minutes=n))


def test_ratings_follow_results_and_order_the_table() -> None:
    matches = [_match(1, "Ants", "Bees", "red"), _match(2, "Cats", "Ants", "blue"),
               _match(3, "Bees", "Cats", "draw")]
    rows = table(matches, list(TEAMS))
    assert rows[0].team == "Ants" and len(rows) == 4  # Dogs, unplayed, has its row too
    assert [r.rating for r in rows] == sorted((r.rating for r in rows), reverse=True)
    ants = rows[0]
    assert (ants.played, ants.won, ants.lost) == (2, 2, 0)
    assert [h.outcome for h in ants.history] == ["won", "won"]
    assert ants.history[0].rating < ants.history[1].rating  # it climbed
    assert ants.history[1].as_dict()["replay"] == "/watch/replay/sub_2"
    bees = next(r for r in rows if r.team == "Bees")
    assert bees.history[-1].outcome == "drawn" and bees.history[-1].score == "0 : 0"


@pytest.fixture
def ladder_service(settings: Settings, token: Callable[..., str]
                   ) -> Iterator[tuple[Served, dict[str, str]]]:
    tokens = {name: token(name, accepts_friendlies=True) for name in TEAMS}
    served = serve(settings.with_(ladder_interval_s=0.2), start_worker=True,
                   pool_factory=lambda _s: FakePool(auto_finish=True),
                   preflight=FakePreflight())
    yield served, tokens
    served.stop()


def test_the_ladder_plays_friendlies_between_four_teams_and_ratings_move(
        ladder_service: tuple[Served, dict[str, str]], token: Callable[..., str]) -> None:
    served, tokens = ladder_service
    for name, secret in tokens.items():
        with served.client(secret) as http:
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
    operator = served.client(token(operator=True))
    deadline = time.monotonic() + 60
    while True:
        done = [m for m in operator.get("/v1/matches").json() if m["state"] == "done"]
        if len(done) >= 6:
            break
        assert time.monotonic() < deadline, operator.get("/v1/matches").json()
        time.sleep(0.2)
    assert all(m["opponent"] in TEAMS for m in done)
    assert {m["team"] for m in done} | {m["opponent"] for m in done} == set(TEAMS)
    league: dict[str, Any] = operator.get("/v1/league").json()
    rows = league["table"]
    assert [r["rating"] for r in rows] == sorted((r["rating"] for r in rows), reverse=True)
    assert [r["rank"] for r in rows] == [1, 2, 3, 4]
    assert len({r["rating"] for r in rows}) > 1 and all(r["played"] >= 1 for r in rows)
    with served.client(tokens["Ants"]) as ants:
        history = ants.get("/v1/league/Ants").json()
        assert history["standing"]["played"] == len(history["history"]) >= 1
        assert history["history"][0]["replay"].startswith("/watch/replay/sub_")
        assert ants.get("/v1/league/Nobody").status_code == 404
    operator.close()


def test_each_role_sees_the_queue_and_matches_it_may(
        start: Callable[..., Served], token: Callable[..., str]) -> None:
    served = start()
    alpha_token, beta_token = token("Alpha"), token("Beta")
    for name, secret in (("Alpha", alpha_token), ("Beta", beta_token)):
        with served.client(secret) as http:
            assert http.put("/v1/team/files/team_config", json=team_doc(name)).status_code == 201
    with served.client(alpha_token) as alpha, served.client(beta_token) as beta, \
            served.client(token(operator=True)) as operator:
        first = alpha.post("/v1/submissions", json={}).json()["id"]
        second = beta.post("/v1/submissions", json={}).json()["id"]
        assert alpha.get("/v1/whoami").json() == {"scope": "team", "team": "Alpha"}
        assert operator.get("/v1/whoami").json()["scope"] == "operator"
        seen = alpha.get("/v1/queue").json()["active"]
        assert [e["own"] for e in seen] == [True, False]
        assert seen[0]["id"] == first and seen[1]["id"] is None
        assert seen[1]["team"] == "another team" and seen[1]["opponent"] == "-"
        assert {e["id"] for e in operator.get("/v1/queue").json()["active"]} == {first, second}
        assert [m["id"] for m in alpha.get("/v1/matches").json()] == [first]
        assert {m["id"] for m in operator.get("/v1/matches").json()} == {first, second}
