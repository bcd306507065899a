"""A registry client for the distribution specification's HTTP API (``/v2/``).

Authentication follows the registry's ``WWW-Authenticate`` challenge (Basic, or Bearer tokens
from its token service; see :mod:`orchestrator.registry.auth`). Listings (catalog, tags) follow
``Link: <...>; rel="next"`` pages. Unreachable registries and 429/5xx answers are retried with
backoff and jitter. Every failure becomes one :class:`RegistryError`, translated here only.

Every request has a deadline (``deadline_s``, 60 s by default) for the whole of it: connect,
headers and body. A registry that answers a byte at a time (a tarpit) is cut off at the
deadline (its socket shut), a failure of kind ``deadline`` that is not retried; an answer over
:data:`MAX_BODY_BYTES` is refused the same way.
"""

from __future__ import annotations

import hashlib
import http.client
import json
import logging
import socket
import threading
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Callable, Iterable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from orchestrator.errors import InfrastructureError
from orchestrator.registry.auth import Credentials, TokenCache, parse_challenges, scope_for
from orchestrator.retry import Backoff, retry

log = logging.getLogger(__name__)

MANIFEST_TYPES = (
    "application/vnd.docker.distribution.manifest.v2+json",
    "application/vnd.oci.image.manifest.v1+json",
    "application/vnd.docker.distribution.manifest.list.v2+json",
    "application/vnd.oci.image.index.v1+json",
)
INDEX_TYPES = MANIFEST_TYPES[2:]
TRANSIENT_STATUS = (429, 500, 502, 503, 504)
USER_AGENT = "hlvs-runner"
DEADLINE_S = 60.0
MAX_BODY_BYTES = 16 << 20
"""The largest answer read from a registry (manifests, listings and tokens are small)."""


class RegistryError(InfrastructureError):
    """A registry request failed: ``url``, HTTP ``status`` (0 when unreachable), ``reason`` and
    ``kind``: auth, denied, not_found, platform (no image for the machine's platform),
    unreachable, transient, deadline (the request outlived its deadline) or failed."""

    def __init__(
        self, *, url: str, status: int, reason: str, kind: str = "failed",
        retry_after_s: float | None = None,
    ) -> None:
        self.url = url
        self.status = status
        self.reason = reason
        self.kind = kind
        self.retry_after_s = retry_after_s  # the server's Retry-After, in seconds
        where = f"HTTP {status}" if status else "unreachable"
        super().__init__(f"registry request {url} failed ({where}): {reason}")

    @property
    def transient(self) -> bool:
        return self.kind in ("unreachable", "transient")


@dataclass(frozen=True, slots=True, kw_only=True)
class Manifest:
    """A manifest's digest, media type and the blobs (config and layers) it needs, by digest."""

    digest: str
    media_type: str
    blobs: Mapping[str, int] = field(default_factory=dict)

    @property
    def size_bytes(self) -> int:
        """Stored (compressed) size: each blob once."""
        return sum(self.blobs.values())


def union_bytes(blob_sets: Iterable[Mapping[str, int]]) -> int:
    """Bytes that several manifests occupy together: each blob (layer, config) counted once.

    The one size rule of the league's team limit, for the registry janitor and for the pull.
    """
    blobs: dict[str, int] = {}
    for blob_set in blob_sets:
        blobs.update(blob_set)
    return sum(blobs.values())


@dataclass(frozen=True, slots=True)
class _Response:
    status: int
    body: bytes
    headers: Mapping[str, str]  # names in lower case


def _lower(items: Any) -> dict[str, str]:
    return {str(name).lower(): str(value) for name, value in items}


class RegistryClient:
    """Reads (and deletes) through a registry's ``/v2/`` API; see the module documentation."""

    def __init__(
        self,
        url: str,
        *,
        credentials: Credentials | None = None,
        username: str | None = None,
        password: str | None = None,
        page_size: int = 100,
        backoff: Backoff | None = None,
        clock: Callable[[], float] = time.monotonic,
        timeout_s: float = 30.0,
        deadline_s: float = DEADLINE_S,
    ) -> None:
        self.url = url.rstrip("/")
        if credentials is None and username:
            credentials = Credentials(username=username, password=password or "")
        self.credentials = credentials
        self.page_size = page_size
        self.backoff = backoff or Backoff(attempts=4, base_s=0.5, cap_s=8.0)
        self.timeout_s = timeout_s
        self.deadline_s = deadline_s
        self.tokens = TokenCache(clock=clock)
        self.token_requests = 0  # token service calls made (tokens are cached per scope)
        self._basic = False  # the registry asked for Basic: send it on every request
        self._bearer: dict[str, str] | None = None  # realm and service of the token service

    # -- listings ---------------------------------------------------------------------------

    def repositories(self) -> list[str]:
        return sorted(self._pages("/v2/_catalog", "repositories"))

    def tags(self, repository: str) -> list[str]:
        return sorted(self._pages(f"/v2/{repository}/tags/list", "tags"))

    def _pages(self, path: str, key: str) -> Iterator[str]:
        page: str | None = f"{path}?n={self.page_size}"
        while page:
            response = self._request("GET", page)
            yield from self._json(response, page).get(key) or []
            page = _next_link(response.headers.get("link", ""))

    # -- manifests --------------------------------------------------------------------------

    def manifest(self, repository: str, reference: str) -> Manifest:
        """The manifest of ``repository:reference`` (tag or digest); an index needs the blobs of
        every image it lists (each blob once)."""
        digest, media_type, document = self._fetch(repository, reference)
        blobs: dict[str, int] = {}
        if _is_index(media_type, document):
            for child in document.get("manifests") or []:
                blobs.update(self.manifest(repository, str(child["digest"])).blobs)
        else:
            blobs = _blobs(document)
        return Manifest(digest=digest, media_type=media_type, blobs=blobs)

    def image(self, repository: str, reference: str, *, platform: str = "linux/amd64") -> Manifest:
        """The manifest of the image a machine of ``platform`` pulls for ``repository:reference``
        (from an index, the entry of that platform)."""
        digest, media_type, document = self._fetch(repository, reference)
        if not _is_index(media_type, document):
            return Manifest(digest=digest, media_type=media_type, blobs=_blobs(document))
        os_name, _, arch = platform.partition("/")
        for child in document.get("manifests") or []:
            wanted = child.get("platform") or {}
            if wanted.get("os") == os_name and wanted.get("architecture") == arch:
                return self.manifest(repository, str(child["digest"]))
        raise RegistryError(
            url=f"{self.url}/v2/{repository}/manifests/{reference}", status=404,
            kind="platform", reason=f"{repository}:{reference} has no image for {platform}",
        )

    def _fetch(self, repository: str, reference: str) -> tuple[str, str, dict[str, Any]]:
        path = f"/v2/{repository}/manifests/{reference}"
        response = self._request("GET", path, accept=", ".join(MANIFEST_TYPES))
        computed = f"sha256:{hashlib.sha256(response.body).hexdigest()}"
        digest = response.headers.get("docker-content-digest") or computed
        document = self._json(response, path)
        media_type = str(document.get("mediaType") or response.headers.get("content-type", ""))
        return digest, media_type, document

    def delete(self, repository: str, digest: str) -> None:
        self._request("DELETE", f"/v2/{repository}/manifests/{digest}")
        log.info("registry %s: deleted %s@%s", self.url, repository, digest)

    # -- requests ---------------------------------------------------------------------------

    def _json(self, response: _Response, path: str) -> dict[str, Any]:
        try:
            document = json.loads(response.body)
        except ValueError as exc:
            raise RegistryError(
                url=self.url + path, status=response.status, reason=f"not JSON: {exc}"
            ) from exc
        if not isinstance(document, dict):
            raise RegistryError(url=self.url + path, status=response.status,
                                reason="expected a JSON object")
        return document

    def _request(self, method: str, path: str, *, accept: str | None = None) -> _Response:
        return retry(
            lambda: self._authorized(method, path, accept),
            transient=lambda exc: isinstance(exc, RegistryError) and exc.transient,
            backoff=self.backoff,
            what=f"registry request {method} {self.url}{path}",
            wait_hint=lambda exc: getattr(exc, "retry_after_s", None),
        )

    def _authorized(self, method: str, path: str, accept: str | None) -> _Response:
        url = self.url + path
        headers = {"Accept": accept} if accept else {}
        scope = scope_for(method, path)
        authorization = self._known_authorization(scope)
        response = self._send(method, url, headers, authorization)
        if response.status != 401:
            return self._checked(method, url, response)
        challenges = parse_challenges(response.headers.get("www-authenticate", ""))
        bearer = next((c for c in challenges if c.scheme == "bearer"), None)
        basic = next((c for c in challenges if c.scheme == "basic"), None)
        if bearer is not None and bearer.realm:
            self._bearer = {"realm": bearer.realm, "service": bearer.params.get("service", "")}
            wanted = bearer.params.get("scope") or scope
            key = (bearer.realm, self._bearer["service"], wanted)
            self.tokens.drop(key)  # refused or absent: fetch a fresh one
            authorization = "Bearer " + self._fetch_token(key)
        elif basic is not None or not challenges:
            if self.credentials is None:
                raise self._auth_error(url, 401, "the registry asks for a user and password")
            if authorization and authorization.startswith("Basic "):
                raise self._auth_error(url, 401, "user or password refused")
            self._basic = True
            authorization = self.credentials.basic()
        else:
            schemes = ", ".join(c.scheme for c in challenges)
            raise self._auth_error(url, 401, f"unsupported authentication scheme {schemes}")
        response = self._send(method, url, headers, authorization)
        if response.status == 401:
            raise self._auth_error(url, 401, "the registry refused the token or the credentials")
        return self._checked(method, url, response)

    def _known_authorization(self, scope: str) -> str | None:
        if self._basic and self.credentials is not None:
            return self.credentials.basic()
        if self._bearer is not None:
            token = self.tokens.get((self._bearer["realm"], self._bearer["service"], scope))
            return f"Bearer {token}" if token else None
        return None

    def _fetch_token(self, key: tuple[str, str, str]) -> str:
        realm, service, scope = key
        query = [("service", service)] if service else []
        query += [("scope", s) for s in scope.split(" ") if s]
        url = realm + ("&" if "?" in realm else "?") + urllib.parse.urlencode(query)
        authorization = self.credentials.basic() if self.credentials else None
        self.token_requests += 1
        response = self._send("GET", url, {}, authorization)
        if response.status in (401, 403):
            raise self._auth_error(url, response.status, "the token service refused the login")
        response = self._checked("GET", url, response)
        try:
            document = json.loads(response.body)
            token = str(document.get("token") or document.get("access_token") or "")
            expires = document.get("expires_in")
        except (ValueError, AttributeError) as exc:
            raise RegistryError(url=url, status=response.status,
                                reason=f"token service answer is not JSON: {exc}") from exc
        if not token:
            raise RegistryError(url=url, status=response.status,
                                reason="token service answered without a token")
        self.tokens.put(key, token, expires_in_s=float(expires) if expires else None)
        log.debug("token for %s from %s", scope, realm)
        return token

    def _auth_error(self, url: str, status: int, detail: str) -> RegistryError:
        user = self.credentials.username if self.credentials else "anonymous"
        host = urllib.parse.urlsplit(self.url).netloc
        return RegistryError(
            url=url, status=status, kind="auth",
            reason=f"authentication failed for {host} (user {user}): {detail}",
        )

    def _checked(self, method: str, url: str, response: _Response) -> _Response:
        if 200 <= response.status < 300:
            return response
        detail = response.body.decode(errors="replace").strip()[:300]
        kind = "failed"
        if response.status == 403:
            kind, detail = "denied", f"access denied: {detail}"
        elif response.status == 404:
            kind = "not_found"
        elif response.status == 405 and method == "DELETE":
            detail = "deletion is disabled on this registry (storage: delete: enabled: true)"
        elif response.status in TRANSIENT_STATUS:
            kind = "transient"
        raise RegistryError(url=url, status=response.status, reason=detail, kind=kind,
                            retry_after_s=_retry_after(response.headers.get("retry-after", "")))

    def _send(
        self, method: str, url: str, headers: Mapping[str, str], authorization: str | None
    ) -> _Response:
        request = urllib.request.Request(url, method=method)
        request.add_header("User-Agent", USER_AGENT)
        for name, value in headers.items():
            request.add_header(name, value)
        if authorization:
            request.add_header("Authorization", authorization)
        watch = _Deadline(self.deadline_s)
        opener = urllib.request.build_opener(_HTTPHandler(watch), _HTTPSHandler(watch))
        try:
            with opener.open(request, timeout=min(self.timeout_s, self.deadline_s)) as answer:
                return _Response(answer.status, _read(answer, watch, url),
                                 _lower(answer.headers.items()))
        except urllib.error.HTTPError as exc:
            return _Response(exc.code, _read(exc, watch, url), _lower(exc.headers.items()))
        except (urllib.error.URLError, OSError, http.client.HTTPException) as exc:
            if watch.expired:
                raise self._deadline_error(url) from None
            reason = getattr(exc, "reason", exc)
            raise RegistryError(url=url, status=0, reason=str(reason), kind="unreachable") from exc
        finally:
            watch.cancel()

    def _deadline_error(self, url: str) -> RegistryError:
        return RegistryError(url=url, status=0, kind="deadline", reason=(
            f"no whole answer within {self.deadline_s:g} s (the registry is too slow)"))


class _Deadline:
    """Shuts the sockets of one request when its deadline passes (blocking reads then fail)."""

    def __init__(self, seconds: float) -> None:
        self.expired = False
        self._sockets: list[socket.socket] = []
        self._lock = threading.Lock()
        self._timer = threading.Timer(seconds, self._expire)
        self._timer.daemon = True
        self._timer.start()

    def watch(self, sock: socket.socket | None) -> None:
        with self._lock:
            if sock is not None:
                self._sockets.append(sock)
            if self.expired:
                self._shut()

    def _expire(self) -> None:
        with self._lock:
            self.expired = True
            self._shut()

    def _shut(self) -> None:
        for sock in self._sockets:
            try:
                sock.shutdown(socket.SHUT_RDWR)
            except OSError:
                pass

    def cancel(self) -> None:
        self._timer.cancel()


def _watched(base: type[http.client.HTTPConnection], watch: _Deadline
             ) -> type[http.client.HTTPConnection]:
    class Watched(base):  # type: ignore[misc,valid-type]
        def connect(self) -> None:
            super().connect()
            watch.watch(self.sock)
    return Watched


class _HTTPHandler(urllib.request.HTTPHandler):
    def __init__(self, watch: _Deadline) -> None:
        super().__init__()
        self._class = _watched(http.client.HTTPConnection, watch)

    def http_open(self, req: urllib.request.Request) -> http.client.HTTPResponse:
        return self.do_open(self._class, req)


class _HTTPSHandler(urllib.request.HTTPSHandler):
    def __init__(self, watch: _Deadline) -> None:
        super().__init__()
        self._class = _watched(http.client.HTTPSConnection, watch)

    def https_open(self, req: urllib.request.Request) -> http.client.HTTPResponse:
        return self.do_open(self._class, req, context=self._context)  # type: ignore[attr-defined]


def _read(answer: Any, watch: _Deadline, url: str) -> bytes:
    """The body, at most :data:`MAX_BODY_BYTES`; a deadline error when the deadline cut it."""
    chunks: list[bytes] = []
    size = 0
    try:
        while True:
            chunk = answer.read(65536)
            if not chunk:
                break
            size += len(chunk)
            if size > MAX_BODY_BYTES:
                raise RegistryError(url=url, status=0, kind="failed", reason=(
                    f"the answer is over {MAX_BODY_BYTES >> 20} MB"))
            chunks.append(chunk)
    except (OSError, http.client.HTTPException) as exc:
        if watch.expired:
            raise RegistryError(url=url, status=0, kind="deadline", reason=(
                "no whole answer within the request's deadline (the registry is too slow)"
            )) from None
        raise RegistryError(url=url, status=0, reason=str(exc), kind="unreachable") from exc
    if watch.expired:
        raise RegistryError(url=url, status=0, kind="deadline", reason=(
            "no whole answer within the request's deadline (the registry is too slow)"))
    return b"".join(chunks)


def _retry_after(value: str) -> float | None:
    """Seconds of a ``Retry-After`` header given in seconds (an HTTP date is not used)."""
    try:
        return max(0.0, float(value)) if value.strip() else None
    except ValueError:
        return None


def _blobs(document: Mapping[str, Any]) -> dict[str, int]:
    """Config and layers of an image manifest, by digest."""
    blobs: dict[str, int] = {}
    for entry in [document.get("config") or {}, *(document.get("layers") or [])]:
        if isinstance(entry, dict) and entry.get("digest"):
            blobs[str(entry["digest"])] = int(entry.get("size", 0))
    return blobs


def _is_index(media_type: str, document: Mapping[str, Any]) -> bool:
    return media_type in INDEX_TYPES or "manifests" in document


def _next_link(header: str) -> str | None:
    """The path of a ``Link: </v2/_catalog?last=x&n=100>; rel="next"`` header."""
    if 'rel="next"' not in header:
        return None
    target = header.split(";", 1)[0].strip().strip("<>")
    parsed = urllib.parse.urlsplit(target)
    return parsed.path + ("?" + parsed.query if parsed.query else "")


__all__ = ["Manifest", "RegistryClient", "RegistryError", "union_bytes"]
