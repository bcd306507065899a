"""Errors of the contracts package: a document that does not match its contract type.

Tree::

    ContractError        a field missing, unknown or of the wrong type (file, field, reason)
    └── UnknownVersion   the document's ``version`` is not one this build reads
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


__all__ = ["ContractError", "UnknownVersion"]
