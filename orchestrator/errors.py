"""Errors of the orchestrator package. Every error carries data and builds its own message.

Tree::

    OrchestratorError
    ├── ConfigError              a configuration file is invalid (carries every problem found)
    ├── InfrastructureError      the Docker engine, a network or the host failed us
    │   ├── EngineUnavailable    no Docker engine answers
    │   │   └── EngineLost       the engine stopped answering while in use (stopped, restarted)
    │   └── RegistryError        the registry API refused or failed (registry/client.py)
    ├── ImageError               an image cannot be used for a robot
    │   ├── ImagePullError       pull failed (auth, unknown tag, unreachable registry)
    │   ├── ImageTooLarge        over the size limit
    │   │   └── TeamImagesTooLarge  a team's images together over the team limit
    │   └── BuildFailed          a project image did not build (engine/images.py)
    ├── MatchFailed              a match ended in a typed failure (see results.FailureClass)
    ├── DeliveryError            a log set could not be delivered (auth, host key, bucket, ...)
    └── ScheduleError            the schedule file or its state is unusable

The CLI maps these to exit codes (``orchestrator.exitcodes``): 2 for ConfigError, 3 for
InfrastructureError, 1 otherwise.
"""

from __future__ import annotations

from dataclasses import dataclass

from orchestrator.exitcodes import ExitCode


class OrchestratorError(Exception):
    """Root of every error the orchestrator package raises."""

    exit_code: int = ExitCode.FAILED


@dataclass(frozen=True, slots=True)
class Problem:
    """One problem in one file.

    Printed as ``file: pointer: message (expected ...; did you mean ...?)``; a problem of the
    whole file (the empty pointer: missing, unreadable, not JSON) as ``file: message``.
    """

    file: str
    pointer: str
    message: str
    expected: str = ""
    suggestion: str = ""
    severity: str = "error"  # or "warning"

    def __str__(self) -> str:
        text = f"{self.file}: {self.pointer + ': ' if self.pointer else ''}{self.message}"
        extras = []
        if self.expected:
            extras.append(f"expected {self.expected}")
        if self.suggestion:
            extras.append(f"did you mean {self.suggestion}?")
        if extras:
            text += f" ({'; '.join(extras)})"
        if self.severity in ("warning", "note"):
            text = f"{self.severity}: " + text
        return text


class ConfigError(OrchestratorError):
    exit_code = ExitCode.INVALID

    def __init__(self, problems: list[Problem]) -> None:
        self.problems = list(problems)
        super().__init__("\n".join(str(p) for p in self.problems))


class InfrastructureError(OrchestratorError):
    exit_code = ExitCode.INFRASTRUCTURE


class EngineUnavailable(InfrastructureError):
    def __init__(self, *, endpoint: str, reason: str) -> None:
        self.endpoint = endpoint
        self.reason = reason
        super().__init__(
            f"no Docker engine answers at {endpoint}: {reason}. "
            "Start one (make setup starts the local engine) or set DOCKER_HOST."
        )


class EngineLost(EngineUnavailable):
    """The engine stopped answering in the middle of a call: it was stopped, restarted or
    crashed (its socket is gone, refuses or closed the connection)."""

    def __init__(self, *, endpoint: str, doing: str, reason: str) -> None:
        self.doing = doing
        InfrastructureError.__init__(
            self, f"the Docker engine at {endpoint} stopped answering ({doing}): {reason}")
        self.endpoint = endpoint
        self.reason = reason


class ImageError(OrchestratorError):
    def __init__(self, *, image: str, reason: str) -> None:
        self.image = image
        self.reason = reason
        super().__init__(f"image {image}: {reason}")


class ImagePullError(ImageError):
    """A pull failed; ``transient`` when trying again may help (registry unreachable, 5xx,
    connection reset), not for a refused login or an unknown tag."""

    def __init__(self, *, image: str, reason: str, transient: bool = False) -> None:
        self.transient = transient
        super().__init__(image=image, reason=reason)


class ImageTooLarge(ImageError):
    def __init__(self, *, image: str, size_bytes: int, limit_bytes: int) -> None:
        self.size_bytes = size_bytes
        self.limit_bytes = limit_bytes
        super().__init__(
            image=image,
            reason=f"{size_bytes / 1e9:.2f} GB is over the limit of {limit_bytes / 1e9:.2f} GB",
        )


class TeamImagesTooLarge(ImageTooLarge):
    """A team's images together (each layer once) are over the team limit; ``size_bytes`` is
    the team's total."""

    def __init__(self, *, image: str, team_bytes: int, limit_bytes: int) -> None:
        self.team_bytes = team_bytes
        self.size_bytes = team_bytes
        self.limit_bytes = limit_bytes
        ImageError.__init__(
            self,
            image=image,
            reason=f"the team's images take {team_bytes / 1e9:.2f} GB together (each layer "
            f"once), over the team limit of {limit_bytes / 1e9:.2f} GB",
        )


class MatchFailed(OrchestratorError):
    def __init__(self, *, match_id: str, failure_class: str, cause: str) -> None:
        self.match_id = match_id
        self.failure_class = failure_class
        self.cause = cause
        super().__init__(f"match {match_id} failed ({failure_class}): {cause}")


class DeliveryError(OrchestratorError):
    def __init__(self, *, team: str, target: str, kind: str, reason: str) -> None:
        self.team = team
        self.target = target
        self.kind = kind  # auth, host_key, bucket, access_denied, path, unreachable, transient
        self.reason = reason
        super().__init__(f"log delivery for {team} to {target} failed ({kind}): {reason}")


class ScheduleError(OrchestratorError):
    pass
