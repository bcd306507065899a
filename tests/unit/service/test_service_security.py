"""The service's defences, piece by piece: sealed secrets and their key, the service's rules
for team files, webhook addresses, body limits, file modes, bounds of numbers."""

from __future__ import annotations

import asyncio
import json
import socket
import stat
from pathlib import Path
from typing import Any

import httpx
import pytest
from cryptography.fernet import Fernet

from orchestrator.private_files import private_dir, write_private
from service import Settings, outbound, sealing, teamfiles
from service.errors import InvalidInput, SettingsError
from service.middleware import BodyLimit
from tests.unit.service.conftest import team_doc


def _mode(path: Path) -> int:
    return stat.S_IMODE(path.stat().st_mode)


# --- sealing ------------------------------------------------------------------------------------


def test_a_sealed_secret_opens_only_with_its_key_and_old_plain_values_pass() -> None:
    sealer = sealing.Sealer(Fernet.generate_key())
    sealed = sealer.seal("hunter2-registry")
    assert sealed.startswith(sealing.PREFIX) and "hunter2" not in sealed
    assert sealer.open(sealed) == "hunter2-registry"
    assert sealer.seal(sealed) == sealed  # never sealed twice
    assert sealer.open("stored-before-sealing") == "stored-before-sealing"
    with pytest.raises(SettingsError):
        sealing.Sealer(Fernet.generate_key()).open(sealed)
    with pytest.raises(SettingsError):
        sealing.Sealer(b"not a key")


def test_documents_have_every_secret_sealed_and_nothing_else() -> None:
    sealer = sealing.Sealer(Fernet.generate_key())
    team = {"name": "A", "registry_auth": {"username": "u", "password": "pw-of-the-registry",
                                           "ecr": {"region": "r", "access_id": "id",
                                                   "access_secret": "secret-of-ecr"}}}
    sealed = sealer.seal_document("team_config", team)
    assert sealed["registry_auth"]["username"] == "u"
    assert sealed["registry_auth"]["ecr"]["access_id"] == "id"
    assert "pw-of-the-registry" not in json.dumps(sealed)
    assert "secret-of-ecr" not in json.dumps(sealed)
    assert sealer.open_document("team_config", sealed) == team
    creds = {"type": "sftp", "credentials": {"hostname": "h", "username": "u", "password": "p2",
                                             "private_key": "-----BEGIN k", "host_key": "x y"}}
    sealed = sealer.seal_document("credentials", creds)
    assert {k for k, v in sealed["credentials"].items() if sealing.is_sealed(v)} == {
        "password", "private_key"}
    assert sealer.open_document("credentials", sealed) == creds
    assert team["registry_auth"]["password"] == "pw-of-the-registry"  # the input is left as it was


def test_the_key_file_is_made_once_0600_beside_the_data_folder(tmp_path: Path) -> None:
    path = sealing.key_file(tmp_path / "data", "")
    assert path == tmp_path / "data.key"
    first = sealing.load_sealer(key="", key_path=path)
    assert _mode(path) == 0o600
    sealed = first.seal("s")
    path.chmod(0o644)
    again = sealing.load_sealer(key="", key_path=path)  # reused, and made private again
    assert again.open(sealed) == "s" and _mode(path) == 0o600
    operator = Fernet.generate_key().decode()
    assert sealing.load_sealer(key=operator, key_path=tmp_path / "unused.key").open(
        sealing.Sealer(operator.encode()).seal("t")) == "t"
    assert not (tmp_path / "unused.key").exists()


# --- the service's rules for team files ---------------------------------------------------------


def _errors(kind: str, document: Any) -> dict[str, str]:
    return {p["pointer"]: p["message"] for p in teamfiles.check(kind, document)
            if p["severity"] == "error"}


def test_registry_logins_must_be_the_teams_own() -> None:
    doc = team_doc()
    doc["registry_auth"] = {"username": "u", "password_env": "AWS_SECRET_ACCESS_KEY"}
    assert "/registry_auth/password_env" in _errors("team_config", doc)
    doc["registry_auth"] = {"ecr": {"region": "us-east-1"}}
    assert "/registry_auth/ecr" in _errors("team_config", doc)
    doc["registry_auth"] = {"ecr": {"region": "us-east-1", "access_id": "AKIA",
                                    "access_secret": "s"}}
    assert _errors("team_config", doc) == {}
    doc["registry_auth"] = {"username": "u", "password": "p"}
    assert _errors("team_config", doc) == {}


def test_a_robot_model_folder_of_the_host_is_refused(tmp_path: Path) -> None:
    doc = team_doc()
    doc["players"]["1"]["model"] = "kid-default"
    assert _errors("team_config", doc) == {}
    doc["players"]["1"]["model"] = str(tmp_path)  # a folder of the host: never read
    assert list(_errors("team_config", doc)) == ["/players/1/model"]


def test_sftp_credentials_are_inline_and_pinned(tmp_path: Path) -> None:
    key = "-----BEGIN OPENSSH PRIVATE KEY-----\nabc\n-----END OPENSSH PRIVATE KEY-----\n"
    pinned = "ssh-ed25519 AAAAC3NzaC1lZDI1NTE5AAAAILxD7/6Y8WqDP6ruY81+KhRD3hE1yx9rKAmI0vF5eFKN"
    body = {"hostname": "h.example.org", "username": "u", "private_key": key,
            "host_key": pinned}
    assert _errors("credentials", {"type": "sftp", "credentials": body}) == {}
    (tmp_path / "id").write_text(key)
    by_path = {**body, "private_key": str(tmp_path / "id"), "known_hosts": "/etc/hosts"}
    errors = _errors("credentials", {"type": "sftp", "credentials": by_path})
    assert {"/credentials/private_key", "/credentials/known_hosts"} <= set(errors)
    unpinned = {k: v for k, v in body.items() if k != "host_key"}
    assert "/credentials/host_key" in _errors("credentials", {"type": "sftp",
                                                              "credentials": unpinned})


def test_a_command_that_does_not_split_is_refused_at_check(tmp_path: Path) -> None:
    from orchestrator.config import check_team

    doc = team_doc()
    doc["players"]["1"]["dockerCmd"] = 'python3 -c "print(1)'
    path = tmp_path / "team_config.json"
    path.write_text(json.dumps(doc))
    problems = [p for p in check_team(path) if p.severity == "error"]
    assert [p.pointer for p in problems] == ["/players/1/dockerCmd"]
    assert "quotation" in problems[0].message


def test_the_upload_checks_the_field_class_the_service_plays() -> None:
    from orchestrator.match.scrimmage import ScrimmageRequest, game_file

    request = ScrimmageRequest(players=1, seed=1, half_duration_s=30.0, wait_before_ready_s=3.0,
                               grace_s=5.0)
    assert game_file(request, "m")["class"] == teamfiles.FIELD_CLASS.name


# --- webhook addresses --------------------------------------------------------------------------


@pytest.mark.parametrize("address", ["127.0.0.1", "169.254.169.254", "10.1.2.3", "192.168.0.1",
                                     "100.64.0.1", "::1", "::ffff:127.0.0.1", "fe80::1",
                                     "224.0.0.1", "0.0.0.0", "fd00::1"])
def test_the_leagues_own_addresses_are_refused(address: str) -> None:
    import ipaddress

    assert not outbound.address_allowed(ipaddress.ip_address(address), ())


def test_public_and_operator_allowed_addresses_pass() -> None:
    import ipaddress

    assert outbound.address_allowed(ipaddress.ip_address("93.184.216.34"), ())
    allowed = outbound.allowed_networks(Settings(webhook_allow="10.20.0.0/16, 127.0.0.1"))
    assert outbound.address_allowed(ipaddress.ip_address("10.20.3.4"), allowed)
    assert not outbound.address_allowed(ipaddress.ip_address("10.21.3.4"), allowed)
    with pytest.raises(SettingsError):
        Settings.from_env({"HLVS_SERVICE_WEBHOOK_ALLOW": "10.0.0.0/40"})


def test_a_name_is_checked_again_when_sent_and_the_checked_address_is_used(
        monkeypatch: pytest.MonkeyPatch) -> None:
    answers = {"hooks.example.org": "93.184.216.34"}

    def getaddrinfo(host: str, port: int, *args: Any, **kwargs: Any) -> list[Any]:
        return [(socket.AF_INET, socket.SOCK_STREAM, 6, "", (answers[host], port))]

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    url = "https://hooks.example.org:8443/hlvs"
    outbound.check_url(url, (), field="/webhook_url")  # a name: accepted when written
    with pytest.raises(InvalidInput):
        outbound.check_url("http://169.254.169.254/", (), field="/webhook_url")
    seen: list[httpx.Request] = []
    client = httpx.Client(transport=httpx.MockTransport(
        lambda request: seen.append(request) or httpx.Response(200)))
    outbound.post(client, url, content=b"{}", headers={}, allowed=())
    assert seen[0].url.host == "93.184.216.34" and seen[0].url.port == 8443
    assert seen[0].headers["Host"] == "hooks.example.org:8443"
    assert seen[0].extensions["sni_hostname"] == "hooks.example.org"
    answers["hooks.example.org"] = "127.0.0.1"  # the name now points home (rebinding)
    with pytest.raises(outbound.Refused, match="not a public address"):
        outbound.post(client, url, content=b"{}", headers={}, allowed=())
    assert len(seen) == 1


# --- body limit, files --------------------------------------------------------------------------


def test_the_body_limit_counts_streamed_bytes() -> None:
    reads = 0

    async def app(scope: Any, receive: Any, send: Any) -> None:
        for _ in range(100):  # a limit that does not hold reads all 100 (then 200)
            if not (await receive()).get("more_body"):
                break
        await send({"type": "http.response.start", "status": 200, "headers": []})
        await send({"type": "http.response.body", "body": b"ok"})

    async def receive() -> dict[str, Any]:
        nonlocal reads
        reads += 1
        return {"type": "http.request", "body": b"x" * 1000, "more_body": True}

    sent: list[dict[str, Any]] = []

    async def send(message: dict[str, Any]) -> None:
        sent.append(message)

    scope = {"type": "http", "method": "POST", "path": "/",
             "headers": [(b"transfer-encoding", b"chunked")]}
    asyncio.run(BodyLimit(app, max_bytes=10_000)(scope, receive, send))
    assert sent[0]["status"] == 413 and reads == 11


def test_private_files_and_folders(tmp_path: Path) -> None:
    folder = private_dir(tmp_path / "a" / "b")
    assert _mode(tmp_path / "a") == 0o700 and _mode(folder) == 0o700
    stale = folder / "f.json.tmp"
    stale.write_text("old")
    stale.chmod(0o644)
    written = write_private(folder / "f.json", "{}")
    assert written.read_text() == "{}" and _mode(written) == 0o600


def test_an_episode_length_out_of_bounds_names_its_field() -> None:
    from envs.errors import EnvConfigError
    from envs.skill import KickEnv

    for value in (1e308, 0.0, float("nan")):
        with pytest.raises(EnvConfigError) as refused:
            KickEnv(max_episode_s=value)
        assert refused.value.field == "max_episode_s"


@pytest.mark.parametrize("seconds", [0.001, 1e9])
def test_max_duration_out_of_bounds_is_refused_at_check(tmp_path: Path, seconds: float) -> None:
    import shutil

    from orchestrator.config import check_game

    example = Path(__file__).parents[3] / "configs" / "examples" / "scrimmage_1v1"
    shutil.copytree(example, tmp_path / "game")
    game = tmp_path / "game" / "game.json"
    game.write_text(json.dumps({**json.loads(game.read_text()), "max_duration": seconds}))
    errors = [p for p in check_game(game) if p.severity == "error"]
    assert [p.pointer for p in errors] == ["/max_duration"]


def test_files_stored_by_an_older_version_are_sealed_and_checked_again(
        start: Any, token: Any, settings: Settings) -> None:
    from sqlalchemy import select

    from service.db import Team, TeamFile, make_engine, session_factory, transaction

    tok = token("Old")
    doc = team_doc("Old")
    doc["registry_auth"] = {"username": "old", "password_env": "HOME", "password": "plain-pw"}
    engine = make_engine(settings.db_url)
    with transaction(session_factory(engine)) as session:
        team = session.scalar(select(Team).where(Team.name == "Old"))
        assert team is not None
        team.webhook_secret = "plain-webhook-secret"
        session.add(TeamFile(team_id=team.id, kind="team_config", version=1,
                             content=json.dumps(doc), sha256="0" * 64, valid=True,
                             problems_json="[]"))
    served = start()
    with transaction(session_factory(engine)) as session:
        row = session.scalar(select(TeamFile))
        team = session.scalar(select(Team).where(Team.name == "Old"))
        assert row is not None and team is not None
        assert "plain-pw" not in row.content and sealing.PREFIX in row.content
        assert team.webhook_secret is not None and sealing.is_sealed(team.webhook_secret)
    engine.dispose()
    with served.client(tok) as http:
        refused = http.post("/v1/submissions", json={})
        assert refused.status_code == 422, refused.text
        assert "/registry_auth/password_env" in [p["pointer"] for p in
                                                 refused.json()["problems"]]


def test_hlvs_submit_sends_a_key_file_as_its_text(tmp_path: Path) -> None:
    from hlvs.commands.client import inline_key

    key = "-----BEGIN OPENSSH PRIVATE KEY-----\nk\n-----END OPENSSH PRIVATE KEY-----\n"
    (tmp_path / "id_team").write_text(key)
    source = tmp_path / "credentials.json"
    document = {"type": "sftp", "credentials": {"hostname": "h", "username": "u",
                                                "private_key": "id_team"}}
    assert inline_key(document, source)["credentials"]["private_key"] == key
    missing = {"type": "sftp", "credentials": {"private_key": "nope"}}
    assert inline_key(missing, source) == missing


def test_the_service_does_not_start_with_a_key_that_opens_nothing(
        start: Any, token: Any, settings: Settings) -> None:
    served = start()
    with served.client(token("Alpha")) as http:
        doc = team_doc("Alpha")
        doc["registry_auth"] = {"username": "a", "password": "pw-alpha-registry"}
        assert http.put("/v1/team/files/team_config", json=doc).status_code == 201
    served.stop()
    with pytest.raises(RuntimeError):  # the lifespan fails: the service does not start
        start(secret_key=Fernet.generate_key().decode())


@pytest.mark.parametrize(("name", "value"), [
    ("HLVS_SERVICE_TEST_PLAYERS", "0"), ("HLVS_SERVICE_TEST_PLAYERS", "9"),
    ("HLVS_SERVICE_THREADS", "0"), ("HLVS_SERVICE_PREFLIGHT_TIMEOUT_S", "-1"),
    ("HLVS_SERVICE_WORKER_POLL_S", "1e30"), ("HLVS_SERVICE_LOG_TARGET_ALLOW", "10.0.0.0/40"),
])
def test_operator_settings_out_of_range_are_refused_at_start(name: str, value: str) -> None:
    with pytest.raises(SettingsError, match=name):
        Settings.from_env({name: value})


@pytest.mark.parametrize("image", ["hlvs-runner/simulator", "hlvs-runner/stub",
                                   "docker.io/hlvs-runner/stub",
                                   "index.docker.io/hlvs-runner/tools"])
def test_the_projects_own_images_fail_a_teams_preflight(image: str, tmp_path: Path) -> None:
    """As found: a team naming the league's own image passed the pre-flight. Refused before
    anything is pulled or the engine is asked."""
    from service.errors import PreflightFailed
    from service.preflight import run

    doc = team_doc("Mallory", image=image)
    with pytest.raises(PreflightFailed) as failed:
        run(teamfiles.validated_team(doc),
            settings=Settings(data_dir=tmp_path, preflight="images"), engine=object())
    assert failed.value.stage == "pull" and "league's own" in failed.value.cause
    assert Settings.from_env({}).team_project_images is False  # a league's default
