"""Errors of the contracts package: a document that does not match its contract type.

Tree::

    ContractError        a field missing, unknown or of the wrong type (file, field, reason)
    └── UnknownVersion   the document's ``version`` is not one this build reads
    ProtocolError        a GameController datagram that is not RGme v12 / RGrt v2 (peer, reason)
"""

from __future__ import annotations


class ContractError(ValueError):
    """A JSON document that does not describe the contract type it was read as."""

    def __init__(self, *, source: str, pointer: str, reason: str) -> None:
        self.source = source
        self.pointer = pointer
        self.reason = reason
        super().__init__(f"{source}: {pointer or '/'}: {reason}")


class UnknownVersion(ContractError):
    def __init__(self, *, source: str, kind: str, version: object, known: int) -> None:
        self.kind = kind
        self.version = version
        self.known = known
        super().__init__(
            source=source,
            pointer="/version",
            reason=f"{kind} version {version!r} is not known to this build (it reads version "
            f"{known}); upgrade hlvs-runner on this side or write version {known}",
        )


class ProtocolError(ValueError):
    """A GameController datagram that does not follow the protocol (names the peer)."""

    def __init__(self, *, peer: str, reason: str, size: int | None = None) -> None:
        self.peer = peer
        self.reason = reason
        self.size = size
        super().__init__(f"{peer}: {reason}" + (f" ({size} bytes)" if size is not None else ""))


__all__ = ["ContractError", "ProtocolError", "UnknownVersion"]
