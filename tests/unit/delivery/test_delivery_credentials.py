"""credentials.json: the league's examples, our examples, precise problems, no leaked secrets."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path

import pytest

from orchestrator.config.credentials import (
    S3Credentials,
    SftpCredentials,
    load_credentials,
)
from orchestrator.errors import ConfigError

EXAMPLES = Path(__file__).resolve().parents[3] / "configs" / "examples" / "credentials"
LEAGUE_SFTP = {
    "type": "sftp",
    "credentials": {
        "hostname": "ab",
        "port": "secret",
        "username": "test_bucket",
        "password": "test_bucket",
    },
}
LEAGUE_S3 = {
    "type": "s3",
    "credentials": {
        "access_id": "test_id",
        "access_secret": "test_secret",
        "bucket": "test-bucket",
    },
}


def write(tmp_path: Path, document: object, name: str = "credentials.json") -> Path:
    path = tmp_path / name
    path.write_text(json.dumps(document), encoding="utf-8")
    path.chmod(0o600)
    return path


def test_league_s3_example_loads_with_defaults(tmp_path: Path) -> None:
    creds = load_credentials(write(tmp_path, LEAGUE_S3))
    assert isinstance(creds, S3Credentials)
    assert (creds.bucket, creds.region, creds.endpoint_url, creds.prefix) == (
        "test-bucket",
        "us-east-1",
        None,
        "",
    )
    assert creds.warnings == ()


def test_league_sftp_example_has_the_right_shape_but_a_non_numeric_port(tmp_path: Path) -> None:
    path = write(tmp_path, LEAGUE_SFTP)
    with pytest.raises(ConfigError) as info:
        load_credentials(path)
    [problem] = info.value.problems
    assert (problem.file, problem.pointer) == (str(path), "/credentials/port")
    assert "'secret' is not a port number" in problem.message
    assert "1 to 65535" in problem.expected


def test_league_sftp_example_with_a_digit_string_port_loads(tmp_path: Path) -> None:
    document = json.loads(json.dumps(LEAGUE_SFTP))
    document["credentials"]["port"] = "2222"
    creds = load_credentials(write(tmp_path, document))
    assert isinstance(creds, SftpCredentials)
    assert creds.port == 2222 and creds.password == "test_bucket"
    assert [w.severity for w in creds.warnings] == ["warning"]  # no pinned host key


def test_secrets_never_appear_in_repr(tmp_path: Path) -> None:
    document = json.loads(json.dumps(LEAGUE_SFTP))
    document["credentials"]["port"] = 22
    document["credentials"]["password"] = "hunter2-secret"
    sftp = load_credentials(write(tmp_path, document))
    s3_document = json.loads(json.dumps(LEAGUE_S3))
    s3_document["credentials"]["access_secret"] = "s3-very-private"
    s3 = load_credentials(write(tmp_path, s3_document, "s3.json"))
    assert "hunter2-secret" not in repr(sftp) and "s3-very-private" not in repr(s3)
    assert "hunter2-secret" not in sftp.describe()


@pytest.mark.parametrize("name", ["sftp_password.json", "s3.json", "s3_compatible.json"])
def test_examples_load(name: str) -> None:
    creds = load_credentials(EXAMPLES / name)
    assert creds.describe()


def test_key_example_loads_next_to_its_key_and_known_hosts(tmp_path: Path) -> None:
    for name in ("sftp_key.json", "known_hosts"):
        shutil.copy(EXAMPLES / name, tmp_path / name)
    (tmp_path / "sftp_key.json").chmod(0o600)
    subprocess.run(
        ["ssh-keygen", "-q", "-t", "ed25519", "-N", "", "-f", str(tmp_path / "id_ed25519")],
        check=True,
    )
    creds = load_credentials(tmp_path / "sftp_key.json")
    assert isinstance(creds, SftpCredentials)
    assert creds.port == 2222 and creds.known_hosts == tmp_path / "known_hosts"
    assert creds.private_key is not None and "PRIVATE KEY" in creds.private_key
    assert creds.warnings == ()


def test_world_readable_file_gives_a_warning(tmp_path: Path) -> None:
    path = write(tmp_path, LEAGUE_S3)
    os.chmod(path, 0o644)
    creds = load_credentials(path)
    [warning] = creds.warnings
    assert warning.severity == "warning" and "0644" in warning.message
    assert "chmod 600" in warning.expected


def test_every_problem_is_reported_at_once_with_pointers(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        {
            "type": "sftp",
            "credentials": {
                "hostname": "h",
                "username": "u",
                "passwd": "x",
                "port": 70000,
                "host_key": "ssh-ed25519 AAAAB3NzaC1yc2EAAAADAQABAAABAQ",
            },
        },
    )
    with pytest.raises(ConfigError) as info:
        load_credentials(path)
    by_pointer = {p.pointer: p for p in info.value.problems}
    assert by_pointer["/credentials/passwd"].suggestion == "'password'"
    assert (
        "/credentials/port" not in by_pointer or "range" in by_pointer["/credentials/port"].message
    )


def test_semantic_problems(tmp_path: Path) -> None:
    path = write(
        tmp_path,
        {
            "type": "sftp",
            "credentials": {
                "hostname": "h",
                "username": "u",
                "port": 70000,
                "private_key": "missing_key",
                "host_key": "ssh-ed25519 AAAAB3NzaC1yc2EAAAADAQABAAABAQ==",
            },
        },
    )
    with pytest.raises(ConfigError) as info:
        load_credentials(path)
    by_pointer = {p.pointer: p for p in info.value.problems}
    assert set(by_pointer) == {
        "/credentials/port",
        "/credentials/private_key",
        "/credentials/host_key",
    }
    assert "out of range" in by_pointer["/credentials/port"].message
    assert "missing_key" in by_pointer["/credentials/private_key"].message
    assert "ssh-rsa key, not ssh-ed25519" in by_pointer["/credentials/host_key"].message


def test_unknown_type_suggests_and_missing_fields_are_named(tmp_path: Path) -> None:
    path = write(tmp_path, {"type": "sftpp", "credentials": {}})
    with pytest.raises(ConfigError) as info:
        load_credentials(path)
    [problem] = info.value.problems
    assert problem.pointer == "/type" and problem.suggestion == "'sftp'"
    path = write(tmp_path, {"type": "s3", "credentials": {"access_id": "a"}})
    with pytest.raises(ConfigError) as info:
        load_credentials(path)
    assert {p.pointer for p in info.value.problems} == {
        "/credentials/access_secret",
        "/credentials/bucket",
    }


def test_unreadable_and_invalid_json(tmp_path: Path) -> None:
    with pytest.raises(ConfigError) as info:
        load_credentials(tmp_path / "nope.json")
    assert "cannot read" in info.value.problems[0].message
    bad = tmp_path / "bad.json"
    bad.write_text("{", encoding="utf-8")
    with pytest.raises(ConfigError) as info:
        load_credentials(bad)
    assert "not valid JSON" in info.value.problems[0].message
