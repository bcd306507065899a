"""The remotes of an environment: named by their addresses, or started and removed by a
launcher (:class:`envs.docker_pool.DockerLauncher` for ``remotes=N``,
:class:`envs.slurm_pool.SlurmLauncher` for ``remotes="slurm:N"``; the launchers are imported when
a pool starts, so that an environment on named remotes does not load the Docker SDK).
"""

from __future__ import annotations

import logging
from typing import Protocol

from envs.errors import EnvConfigError, RemoteError
from envs.remote import (
    SLURM_SCHEME,
    RemoteAddress,
    RemoteSession,
    parse_remotes,
    parse_slurm,
)
from envs.session_spec import SessionSpec

log = logging.getLogger(__name__)


class Launcher(Protocol):
    """Starts and removes remote simulators (:class:`envs.docker_pool.DockerLauncher`,
    :class:`envs.slurm_pool.SlurmLauncher`)."""

    def start(self, count: int) -> list[RemoteAddress]: ...

    def replace(self, index: int) -> RemoteAddress: ...

    def diagnose(self, index: int) -> str | None: ...

    def close(self) -> None: ...


class RemotePool:
    """The remotes of one environment (or vector environment)."""

    def __init__(self, addresses: list[RemoteAddress], launcher: Launcher | None) -> None:
        self.addresses = addresses
        self.launcher = launcher

    @classmethod
    def open(cls, remotes: int | str, *, image: str | None = None) -> RemotePool:
        launcher: Launcher
        if isinstance(remotes, str) and remotes.startswith(SLURM_SCHEME):
            count, options = parse_slurm(remotes)
            from envs.slurm_pool import SlurmLauncher, SlurmOptions

            launcher = SlurmLauncher(SlurmOptions.from_query(options), image=image)
        elif isinstance(remotes, str):
            return cls(parse_remotes(remotes), None)
        elif isinstance(remotes, bool) or not isinstance(remotes, int) or remotes < 1:
            raise EnvConfigError(
                field="remotes", value=remotes,
                expected="None, an integer >= 1, 'hlvs://host:port,...' or 'slurm:N'",
            )  # fmt: skip
        else:
            from envs.docker_pool import DockerLauncher

            launcher, count = DockerLauncher(image=image), remotes
        try:
            return cls(launcher.start(count), launcher)
        except BaseException:
            launcher.close()
            raise

    def __len__(self) -> int:
        return len(self.addresses)

    def session(self, index: int, spec: SessionSpec) -> RemoteSession:
        launcher = self.launcher
        diagnose = (lambda: launcher.diagnose(index)) if launcher is not None else None
        return RemoteSession(self.addresses[index], spec, diagnose=diagnose)

    def replace(self, index: int, spec: SessionSpec) -> RemoteSession:
        """A new remote in place of a crashed one (only for remotes the pool started)."""
        if self.launcher is None:
            raise RemoteError(
                address=str(self.addresses[index]),
                reason="crashed, and it was started by someone else: start it again",
            )
        self.addresses[index] = self.launcher.replace(index)
        log.info("remote %d replaced by %s", index, self.addresses[index])
        return self.session(index, spec)

    def close(self) -> None:
        if self.launcher is not None:
            self.launcher.close()
