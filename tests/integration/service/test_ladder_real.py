"""The ladder against the local Docker pool: the ladder schedules a real friendly between two
teams that accept friendlies, the match plays, and its result moves both teams' ratings."""

from __future__ import annotations

import json
import os
import time
from typing import Any

import pytest

from contracts import MIN_PLAYING_S, MIN_READY_S
from service import Settings
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import serve
from tests.integration.service.test_real_matches import real_settings, team_doc  # noqa: F401

pytestmark = [pytest.mark.docker, pytest.mark.slow,
              pytest.mark.skipif(os.geteuid() != 0,
                                 reason="matches need root (host controls)")]


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_ladder_plays_a_real_friendly_and_rates_it(
        real_settings: Settings, make_token: TokenMaker) -> None:  # noqa: F811
    # What is checked is that a friendly the ladder scheduled is played and rated, not how long
    # it plays: halves of the documented minimum of play and the shortest READY (the service's
    # own test matches keep 40 s halves, as test_real_matches.py plays them).
    settings = real_settings.with_(ladder_every_s=3600.0, preflight="images", video=False,
                                   test_half_duration_s=MIN_PLAYING_S,
                                   test_ready_duration_s=MIN_READY_S)
    served = serve(settings, start_worker=True)
    clients: dict[str, Any] = {}
    try:
        clients = {name: served.client(make_token(team=name, accepts_friendlies=True))
                   for name in ("Alpha", "Beta")}
        for name, http in clients.items():
            uploaded = http.put("/v1/team/files/team_config", json=team_doc(name))
            assert uploaded.status_code == 201, uploaded.text
        deadline = time.monotonic() + 240
        ladder: dict[str, object] = {}
        while time.monotonic() < deadline:
            ladder = clients["Beta"].get("/v1/ladder").json()
            if ladder["matches_rated"] == 1:
                break
            time.sleep(1.0)
        assert ladder["matches_rated"] == 1, ladder
        played = [s for http in clients.values()
                  for s in http.get("/v1/submissions").json()]
        assert len(played) == 1 and played[0]["state"] == "done" and not played[0]["charged"]
        sid, team = played[0]["id"], played[0]["team"]
        results = clients[team].get(f"/v1/submissions/{sid}/results").json()
        assert results["play"]["halves_playing"], json.dumps(results["play"])
        teams = {t["team"]: t for t in ladder["teams"]}  # type: ignore[union-attr]
        assert set(teams) == {"Alpha", "Beta"}
        assert all(t["played"] == 1 and t["sigma"] < 25 / 3 for t in teams.values())
        score = results["score"]
        red, blue = team, played[0]["opponent"]
        assert (teams[red]["goals_for"], teams[blue]["goals_for"]) == (score["red"],
                                                                     score["blue"])
        if score["red"] == score["blue"]:
            assert teams[red]["rating"] == teams[blue]["rating"] and teams[red]["drawn"] == 1
        else:
            winner = red if score["red"] > score["blue"] else blue
            assert teams[winner]["won"] == 1 and teams[winner]["rank"] == 1
    finally:
        for http in clients.values():
            http.close()
        served.stop()
