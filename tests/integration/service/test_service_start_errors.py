"""``hlvs serve`` and ``hlvs admin`` that cannot open the service's storage: one line naming the
setting and what was expected, exit status 2, no traceback, nothing stored lost. Real processes,
a real sealed secret and the real PostgreSQL driver (a closed port; the test server with a
wrong password)."""

from __future__ import annotations

import json
import os
import socket
import subprocess
import sys
from pathlib import Path

import pytest
from cryptography.fernet import Fernet

from service import Settings
from tests.integration.service.conftest import TokenMaker
from tests.integration.service.harness import free_port, serve
from tests.unit.service.conftest import team_doc

HLVS = [sys.executable, "-m", "hlvs"]


def _run(argv: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess[str]:
    return subprocess.run([*HLVS, *argv], env={**os.environ, **env}, cwd=cwd,
                          capture_output=True, text=True, timeout=120, check=False)  # fmt: skip


def _one_line(proc: subprocess.CompletedProcess[str], *words: str) -> str:
    assert proc.returncode == 2, (proc.returncode, proc.stderr[-2000:])
    assert "Traceback" not in proc.stderr, proc.stderr[-2000:]
    lines = [line for line in proc.stderr.splitlines() if line.startswith("hlvs: ")]
    assert len(lines) == 1, proc.stderr[-2000:]
    for word in words:
        assert word in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("db_url", ["sqlite"], indirect=True)
def test_serve_with_another_secret_key_says_which_setting_and_keeps_the_secrets(
    tmp_path: Path, settings: Settings, make_token: TokenMaker
) -> None:
    key = Fernet.generate_key().decode()
    sealed = settings.with_(secret_key=key)
    served = serve(sealed)
    try:
        with served.client(make_token(team="Alpha")) as http:
            doc = team_doc("Alpha")
            doc["registry_auth"] = {"username": "a", "password": "pw-alpha-registry"}
            assert http.put("/v1/team/files/team_config", json=doc).status_code == 201
    finally:
        served.stop()
    env = {"HLVS_SERVICE_DATA_DIR": str(settings.data_dir),
           "HLVS_SERVICE_DATABASE_URL": settings.db_url}
    wrong = _run(["serve", "--port", str(free_port()), "--no-worker"],
                 {**env, "HLVS_SERVICE_SECRET_KEY": Fernet.generate_key().decode()}, tmp_path)
    _one_line(wrong, "HLVS_SERVICE_SECRET_KEY", "the key the stored secrets were sealed with")
    # the right key still opens what was stored
    listed = _run(["admin", "team", "list"],
                  {**env, "HLVS_SERVICE_SECRET_KEY": key}, tmp_path)
    assert listed.returncode == 0, listed.stderr[-2000:]
    assert "Alpha" in listed.stdout
    again = serve(sealed)
    try:
        with again.client(make_token(team="Alpha")) as http:
            answer = http.get("/v1/team/files/team_config")
            assert answer.status_code == 200, answer.text
    finally:
        again.stop()


@pytest.mark.parametrize("command", [["serve", "--no-worker"], ["admin", "team", "list"]])
def test_an_unreachable_database_is_one_line_with_its_password_hidden(
    tmp_path: Path, command: list[str]
) -> None:
    port = free_port()
    url = f"postgresql+psycopg://hlvs:pw-not-shown@127.0.0.1:{port}/league"
    argv = [*command, "--port", str(free_port())] if command[0] == "serve" else command
    proc = _run(argv, {"HLVS_SERVICE_DATABASE_URL": url}, tmp_path)
    line = _one_line(proc, "HLVS_SERVICE_DATABASE_URL", f"127.0.0.1:{port}/league",
                     "a database that answers", "refused")
    assert "pw-not-shown" not in proc.stderr + proc.stdout and "***" in line


def test_a_wrong_password_of_the_real_server_is_one_line(tmp_path: Path) -> None:
    from sqlalchemy.engine import make_url

    from tests.integration.service.postgres import test_database_url

    url = test_database_url()
    if url is None:
        if os.geteuid() == 0 and Path("/etc/debian_version").is_file():
            pytest.fail("no test PostgreSQL: run scripts/ensure-postgres.sh (make test does)")
        pytest.skip("PostgreSQL is set up only on Debian as root (scripts/ensure-postgres.sh)")
    wrong = make_url(url).set(password="not-its-password").render_as_string(hide_password=False)
    proc = _run(["admin", "token", "list"],
                {"HLVS_SERVICE_DATABASE_URL": wrong}, tmp_path)
    line = _one_line(proc, "HLVS_SERVICE_DATABASE_URL", "a database that answers")
    assert "not-its-password" not in proc.stderr and "password" in line.lower()
    assert json.dumps(line)  # one printable line


def test_a_busy_port_is_one_line_before_anything_starts(tmp_path: Path) -> None:
    """uvicorn binds after the app's startup, whose worker could have taken a queued match by
    then: ``hlvs serve`` binds first."""
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        data = tmp_path / "service-data"
        proc = _run(["serve", "--port", str(port)], {"HLVS_SERVICE_DATA_DIR": str(data)},
                    tmp_path)
    _one_line(proc, "--port", f"127.0.0.1:{port}", "in use")
    assert not data.exists()  # nothing opened, no worker started
    assert "Application startup" not in proc.stderr


@pytest.mark.parametrize("command", [["serve", "--no-worker"], ["admin", "team", "list"]])
@pytest.mark.parametrize("where", ["a file", "below a file"])
def test_a_data_folder_that_cannot_be_made_is_one_line(
    tmp_path: Path, command: list[str], where: str
) -> None:
    in_the_way = tmp_path / "service-data"
    in_the_way.write_text("an operator's notes\n")
    data = in_the_way if where == "a file" else in_the_way / "league"
    argv = [*command, "--port", str(free_port())] if command[0] == "serve" else command
    proc = _run(argv, {"HLVS_SERVICE_DATA_DIR": str(data)}, tmp_path)
    _one_line(proc, "HLVS_SERVICE_DATA_DIR", str(data), "a folder the service can create",
              f"{in_the_way} is a file, not a folder")
    assert in_the_way.read_text() == "an operator's notes\n"  # nothing lost
