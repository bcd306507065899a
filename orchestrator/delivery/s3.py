"""S3 uploader (the only boto3 user of the delivery package).

Works with AWS S3 and S3-compatible stores (``endpoint_url``, path-style addressing). Large
files go up in parts (``TransferConfig``); an object appears only when its upload completes.
The league asks teams to grant ``s3:PutObject`` only, so a 403 on a read (HEAD) is not an error:
the file is simply uploaded again.
"""

from __future__ import annotations

import logging
import urllib.parse
from collections.abc import Callable
from pathlib import Path
from typing import Any

import boto3
import botocore.config
import botocore.exceptions
from boto3.exceptions import S3UploadFailedError
from boto3.s3.transfer import TransferConfig
from botocore.awsrequest import AWSHTTPConnectionPool, AWSHTTPSConnectionPool

from orchestrator.config.credentials import S3Credentials
from orchestrator.delivery.addresses import AddressRefused, IPNetwork, resolve
from orchestrator.errors import DeliveryError

__all__ = ["S3Uploader", "create_bucket"]

log = logging.getLogger(__name__)

MULTIPART_THRESHOLD_BYTES = 16 << 20
MULTIPART_CHUNK_BYTES = 16 << 20
CONNECT_TIMEOUT_S = 10.0
READ_TIMEOUT_S = 60.0
_AUTH_CODES = frozenset(
    {
        "InvalidAccessKeyId",
        "SignatureDoesNotMatch",
        "InvalidToken",
        "ExpiredToken",
        "AuthorizationHeaderMalformed",
    }
)
_DENIED_CODES = frozenset({"AccessDenied", "AllAccessDisabled", "403", "Forbidden"})
_BUCKET_CODES = frozenset({"NoSuchBucket", "404", "NotFound", "InvalidBucketName"})


class S3Uploader:
    """A boto3 S3 client bound to one bucket and prefix; use :meth:`connect`."""

    def __init__(self, *, client: Any, credentials: S3Credentials, team: str) -> None:
        self._client = client
        self._credentials = credentials
        self._team = team
        self._transfer = TransferConfig(
            multipart_threshold=MULTIPART_THRESHOLD_BYTES,
            multipart_chunksize=MULTIPART_CHUNK_BYTES,
            max_concurrency=4,
        )

    @property
    def target(self) -> str:
        return self._credentials.describe()

    @classmethod
    def connect(cls, credentials: S3Credentials, *, team: str,
                allowed: tuple[IPNetwork, ...] | None = None,
                allow_setting: str = "") -> S3Uploader:
        """Open a client; with ``allowed``, the ``endpoint_url`` host is resolved and checked
        now and every connection of the client goes to the address checked
        (:func:`orchestrator.delivery.targets.open_uploader`)."""
        pin: tuple[str, str] | None = None
        if allowed is not None and credentials.endpoint_url:
            parsed = urllib.parse.urlsplit(credentials.endpoint_url)
            host = parsed.hostname or ""
            try:
                port = parsed.port or (443 if parsed.scheme == "https" else 80)
                pin = (host, str(resolve(host, port, allowed, allow_setting)))
            except (AddressRefused, ValueError) as exc:
                raise DeliveryError(team=team, target=credentials.describe(), kind="address",
                                    reason=str(exc)) from None
        client = _client(credentials, pin=pin)
        uploader = cls(client=client, credentials=credentials, team=team)
        uploader._check_bucket()
        log.info("team %s: connected to %s", team, uploader.target)
        return uploader

    def upload(self, local_path: Path, remote_rel_path: str) -> None:
        key = self._key(remote_rel_path)
        try:
            self._client.upload_file(
                str(local_path), self._credentials.bucket, key, Config=self._transfer
            )
        except S3UploadFailedError as exc:
            cause = exc.__cause__ or exc.__context__
            raise self._translate(cause if cause is not None else exc, key) from exc
        except (botocore.exceptions.BotoCoreError, botocore.exceptions.ClientError) as exc:
            raise self._translate(exc, key) from exc

    def exists(self, remote_rel_path: str, size: int) -> bool:
        key = self._key(remote_rel_path)
        try:
            head = self._client.head_object(Bucket=self._credentials.bucket, Key=key)
        except botocore.exceptions.ClientError as exc:
            if _code(exc) in _BUCKET_CODES | _DENIED_CODES:
                return False  # missing, or we may not look: upload it (again)
            raise self._translate(exc, key) from exc
        except botocore.exceptions.BotoCoreError as exc:
            raise self._translate(exc, key) from exc
        return int(head.get("ContentLength", -1)) == size

    def close(self) -> None:
        self._client.close()

    def _key(self, remote_rel_path: str) -> str:
        prefix = self._credentials.prefix
        return f"{prefix}/{remote_rel_path}" if prefix else remote_rel_path

    def _check_bucket(self) -> None:
        try:
            self._client.head_bucket(Bucket=self._credentials.bucket)
        except botocore.exceptions.ClientError as exc:
            if _code(exc) in _DENIED_CODES:
                return  # a PutObject-only account may not look at the bucket
            raise self._translate(exc, "") from exc
        except botocore.exceptions.BotoCoreError as exc:
            raise self._translate(exc, "") from exc

    def _translate(self, exc: BaseException, key: str) -> DeliveryError:
        bucket = self._credentials.bucket
        where = f"s3://{bucket}/{key}" if key else f"bucket {bucket!r}"
        kind, reason = "transient", f"{where}: {exc}"
        if isinstance(exc, botocore.exceptions.EndpointConnectionError):
            kind, reason = "unreachable", f"no S3 server answers: {exc}"
        elif isinstance(exc, botocore.exceptions.ClientError):
            code = _code(exc)
            status = int(exc.response.get("ResponseMetadata", {}).get("HTTPStatusCode", 0))
            if code in _AUTH_CODES:
                kind, reason = "auth", f"the access id or secret was rejected ({code})"
            elif code in _BUCKET_CODES:
                kind, reason = "bucket", f"the bucket {bucket!r} does not exist ({code})"
            elif code in _DENIED_CODES or status == 403:
                kind, reason = (
                    "access_denied",
                    f"the account may not write {where} ({code}); "
                    "grant it s3:PutObject on the bucket",
                )
            elif 400 <= status < 500:
                kind, reason = "path", f"{where} was refused: {code} {exc}"
        return DeliveryError(team=self._team, target=self.target, kind=kind, reason=reason)


def create_bucket(credentials: S3Credentials) -> None:
    """Create the bucket of ``credentials`` (for local test servers and the benchmark)."""
    client = _client(credentials)
    try:
        client.create_bucket(Bucket=credentials.bucket)
    finally:
        client.close()


def _client(credentials: S3Credentials, *, pin: tuple[str, str] | None = None) -> Any:
    """A boto3 client; ``pin`` = (host name, address): its connections go to that address
    (the name stays in the Host header and TLS), and to no other host."""
    config = botocore.config.Config(
        connect_timeout=CONNECT_TIMEOUT_S,
        read_timeout=READ_TIMEOUT_S,
        retries={"total_max_attempts": 1},  # deliver.py retries with its own backoff
        s3={"addressing_style": "path" if credentials.endpoint_url else "auto"},
        max_pool_connections=16,
    )
    client = boto3.client(
        "s3",
        aws_access_key_id=credentials.access_id,
        aws_secret_access_key=credentials.access_secret,
        region_name=credentials.region,
        endpoint_url=credentials.endpoint_url,
        config=config,
    )
    if pin is not None:
        _pin_connections(client, *pin)
    return client


def _pin_connections(client: Any, name: str, address: str) -> None:
    """Every new connection of ``client`` to ``name`` goes to ``address``; one to any other
    host (a redirect) is refused. The name is kept for the Host header, SNI and the
    certificate check: only the socket's address changes."""
    session = client._endpoint.http_session
    pools = {}
    for scheme, base in (("http", AWSHTTPConnectionPool), ("https", AWSHTTPSConnectionPool)):
        pinned_class = type(f"Pinned{base.ConnectionCls.__name__}", (base.ConnectionCls,),
                            {"_new_conn": _pinned_new_conn(name, address)})
        pools[scheme] = type(f"Pinned{base.__name__}", (base,),
                             {"ConnectionCls": pinned_class})
    session._pool_classes_by_scheme = pools
    session._manager.pool_classes_by_scheme = pools


def _pinned_new_conn(name: str, address: str) -> Callable[[Any], Any]:
    def _new_conn(self: Any) -> Any:
        original = self._dns_host
        host = str(original).rstrip(".").lower()
        if host != name.rstrip(".").lower():
            raise OSError(f"a connection to {host} was refused (only {name} is reachable)")
        self._dns_host = address
        try:
            return super(type(self), self)._new_conn()
        finally:
            self._dns_host = original
    return _new_conn


def _code(exc: botocore.exceptions.ClientError) -> str:
    return str(exc.response.get("Error", {}).get("Code", ""))
