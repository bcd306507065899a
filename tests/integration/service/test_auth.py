"""Tokens and the team-token dependency, against the real app over HTTP."""

from __future__ import annotations

from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import Served


def test_requests_without_or_with_bad_tokens_get_401_saying_why(
        served: Served, make_token: TokenMaker) -> None:
    with served.client() as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 401
        assert answer.json()["reason"] == "missing"
        assert answer.headers["www-authenticate"] == "Bearer"
    with served.client("not-a-token") as http:
        assert http.get("/v1/team").json()["reason"] == "malformed"
    good = make_token(team="Alpha")
    forged = good[:-4] + ("AAAA" if not good.endswith("AAAA") else "BBBB")
    with served.client(forged) as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 401 and answer.json()["reason"] == "unknown"
        assert forged not in answer.text  # never echoed


def test_team_token_reads_its_team_and_expired_or_revoked_tokens_say_so(
        served: Served, make_token: TokenMaker) -> None:
    from service import tokens
    from service.db import make_engine, session_factory, transaction

    token = make_token(team="Alpha", email="alpha@example.org")
    with served.client(token) as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 200, answer.text
        assert answer.json()["name"] == "Alpha"
        assert answer.json()["email"] == "alpha@example.org"
    expired = make_token(team="Alpha", days=-1)
    with served.client(expired) as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 401
        assert answer.json()["reason"] == "expired"
        assert "expired at" in answer.json()["message"]
    token_id = token.split("_")[1]
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        tokens.revoke(session, token_id)
    engine.dispose()
    with served.client(token) as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 401
        assert answer.json()["reason"] == "revoked"
        assert token_id in answer.json()["message"]


def test_operator_token_is_refused_where_a_team_token_is_needed(
        served: Served, make_token: TokenMaker) -> None:
    with served.client(make_token(operator=True)) as http:
        answer = http.get("/v1/team")
        assert answer.status_code == 401
        assert answer.json()["reason"] == "scope"


def test_tokens_are_stored_hashed(served: Served, make_token: TokenMaker) -> None:
    from sqlalchemy import select

    from service.db import Token, make_engine, session_factory, transaction

    token = make_token(team="Alpha")
    engine = make_engine(served.settings.db_url)
    with transaction(session_factory(engine)) as session:
        stored = session.scalars(select(Token)).all()
    engine.dispose()
    secret = token.split("_", 2)[2]
    assert stored and all(secret not in (row.secret_sha256 + row.id) for row in stored)


def test_openapi_document_lists_the_team_routes(served: Served) -> None:
    with served.client() as http:
        document = http.get("/openapi.json").json()
    assert "/v1/team" in document["paths"]
    assert "/v1/team/files/{kind}" in document["paths"]
    assert "HTTPBearer" in document["components"]["securitySchemes"]
