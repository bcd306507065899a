"""A token service on loopback for a real registry configured with ``auth: token``.

It does what Docker Hub's, Harbor's or GitLab's token services do for the distribution registry:
``GET /token?service=...&scope=repository:NAME:pull,push`` with HTTP Basic credentials returns a
JWT (RS256) that grants the scopes the user may have; the registry checks the signature against
the certificate given as its ``rootcertbundle`` (the key is named by its ``kid``, the libtrust
fingerprint the registry computes from that certificate). Policy: a user may pull, push and
delete in the repositories under its own name; ``janitor`` may do everything, the catalog too;
anonymous users get no access. Every token request is recorded.
"""

from __future__ import annotations

import base64
import datetime
import hashlib
import json
import secrets
import threading
import time
import urllib.parse
from dataclasses import dataclass, field
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any

from cryptography import x509
from cryptography.hazmat.primitives import hashes, serialization
from cryptography.hazmat.primitives.asymmetric import padding, rsa
from cryptography.x509.oid import NameOID

ISSUER = "hlvs-test-issuer"
SERVICE = "hlvs-test-registry"


def _b64url(data: bytes) -> str:
    return base64.urlsafe_b64encode(data).rstrip(b"=").decode()


def libtrust_kid(public_key: rsa.RSAPublicKey) -> str:
    """The key id the distribution registry derives from a certificate's public key."""
    der = public_key.public_bytes(
        serialization.Encoding.DER, serialization.PublicFormat.SubjectPublicKeyInfo
    )
    digest = base64.b32encode(hashlib.sha256(der).digest()[:30]).decode().rstrip("=")
    return ":".join(digest[i : i + 4] for i in range(0, len(digest), 4))


@dataclass
class TokenIssuer:
    """The token service; ``start()`` serves it on 127.0.0.1 and writes the certificate."""

    folder: Path
    users: dict[str, str]
    expires_in_s: int = 300
    requests: list[dict[str, Any]] = field(default_factory=list)
    port: int = 0

    def __post_init__(self) -> None:
        self.key = rsa.generate_private_key(public_exponent=65537, key_size=2048)
        name = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, ISSUER)])
        now = datetime.datetime.now(datetime.UTC)
        cert = (
            x509.CertificateBuilder()
            .subject_name(name)
            .issuer_name(name)
            .public_key(self.key.public_key())
            .serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(days=1))
            .not_valid_after(now + datetime.timedelta(days=1))
            .add_extension(x509.BasicConstraints(ca=True, path_length=None), critical=True)
            .sign(self.key, hashes.SHA256())
        )
        self.folder.mkdir(parents=True, exist_ok=True)
        self.cert_path = self.folder / "token-cert.pem"
        self.cert_path.write_bytes(cert.public_bytes(serialization.Encoding.PEM))
        self.kid = libtrust_kid(self.key.public_key())
        self._lock = threading.Lock()

    @property
    def realm(self) -> str:
        return f"http://127.0.0.1:{self.port}/token"

    def allowed(self, user: str | None, scope: str) -> dict[str, Any] | None:
        kind, _, rest = scope.partition(":")
        name, _, actions = rest.rpartition(":")
        wanted = [a for a in actions.split(",") if a]
        if user is None:
            return None
        if user == "janitor":
            granted = wanted
        elif kind == "repository" and name.startswith(user + "/"):
            granted = [a for a in wanted if a in ("pull", "push", "delete", "*")]
        else:
            granted = []
        return {"type": kind, "name": name, "actions": granted}

    def token(self, user: str | None, scopes: list[str]) -> str:
        now = int(time.time())
        access = [a for a in (self.allowed(user, s) for s in scopes) if a is not None]
        claims = {
            "iss": ISSUER, "sub": user or "", "aud": SERVICE, "exp": now + self.expires_in_s,
            "nbf": now - 10, "iat": now, "jti": secrets.token_hex(8), "access": access,
        }
        header = {"typ": "JWT", "alg": "RS256", "kid": self.kid}
        signing_input = (
            _b64url(json.dumps(header).encode()) + "." + _b64url(json.dumps(claims).encode())
        )
        signature = self.key.sign(signing_input.encode(), padding.PKCS1v15(), hashes.SHA256())
        return signing_input + "." + _b64url(signature)

    def start(self) -> ThreadingHTTPServer:
        issuer = self

        class Handler(BaseHTTPRequestHandler):
            def do_GET(self) -> None:  # noqa: N802 (http.server's naming)
                url = urllib.parse.urlsplit(self.path)
                query = urllib.parse.parse_qs(url.query)
                user = issuer._user(self.headers.get("Authorization", ""))
                scopes = query.get("scope", [])
                with issuer._lock:
                    issuer.requests.append(
                        {"user": user, "scopes": scopes, "service": query.get("service", [""])[0],
                         "agent": self.headers.get("User-Agent", "")}
                    )
                if url.path != "/token":
                    self._answer(404, {"error": "not found"})
                elif user is False:
                    self._answer(401, {"errors": [{"code": "UNAUTHORIZED"}]})
                else:
                    token = issuer.token(user or None, scopes)
                    self._answer(200, {"token": token, "access_token": token,
                                       "expires_in": issuer.expires_in_s,
                                       "issued_at": time.strftime("%Y-%m-%dT%H:%M:%SZ",
                                                                  time.gmtime())})

            def _answer(self, status: int, body: dict[str, Any]) -> None:
                data = json.dumps(body).encode()
                self.send_response(status)
                self.send_header("Content-Type", "application/json")
                self.send_header("Content-Length", str(len(data)))
                self.end_headers()
                self.wfile.write(data)

            def log_message(self, format: str, *args: Any) -> None:
                pass

        server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.port = server.server_address[1]
        threading.Thread(target=server.serve_forever, daemon=True).start()
        return server

    def _user(self, header: str) -> str | None | bool:
        """The user of a Basic header; None when anonymous; False when the password is wrong."""
        if not header.startswith("Basic "):
            return None
        user, _, password = base64.b64decode(header[6:]).decode().partition(":")
        return user if self.users.get(user) == password else False


__all__ = ["ISSUER", "SERVICE", "TokenIssuer", "libtrust_kid"]
