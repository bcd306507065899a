"""Errors of the cluster package. Every error carries data and builds its own message.

Tree::

    ClusterError
    └── PoolError            the match pool could not start, query or stop a match (the Slurm
                             controller is down, the job vanished, the account is unknown)

The submission service answers a ``PoolError`` met while serving a request with HTTP 503
(``service.app``); the command line maps it to the infrastructure exit code.
"""

from __future__ import annotations


class ClusterError(Exception):
    """Root of every error the cluster package raises."""

    exit_code = 3  # infrastructure (orchestrator.exitcodes.ExitCode.INFRASTRUCTURE)


class PoolError(ClusterError):
    kind = "pool_unavailable"

    def __init__(self, *, handle: str, reason: str) -> None:
        self.handle = handle
        self.reason = reason
        super().__init__(f"match pool, job {handle}: {reason}")

    def fields(self) -> dict[str, str]:
        """The fields the error adds to a JSON error body."""
        return {"handle": self.handle, "reason": self.reason}


__all__ = ["ClusterError", "PoolError"]
