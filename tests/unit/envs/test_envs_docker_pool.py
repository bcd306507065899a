"""The Docker launcher of remotes chooses the nearest address a remote answers on (no engine:
its container side is replaced; tests/integration/envs runs it on a real one)."""

from __future__ import annotations

from pathlib import Path

import pytest

import envs.docker_pool as docker_pool
from envs.docker_pool import DockerLauncher
from envs.remote import RemoteAddress
from envs.wire import WireError

TCP = RemoteAddress("172.17.0.2", 7700)


def _launcher(socket_path: Path) -> DockerLauncher:
    launcher = object.__new__(DockerLauncher)  # no engine: only what _healthy reads
    launcher.sockets = {"cid": str(socket_path)}
    launcher.health_timeout_s = 5.0
    launcher.diagnose = lambda index: None  # type: ignore[method-assign]
    launcher._candidates = lambda cid: [TCP]  # type: ignore[method-assign]
    return launcher


def test_a_socket_bound_while_the_candidates_were_listed_is_still_chosen(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """The remote binds its socket, then its port: a port that answers after the candidates
    were listed (without the socket) means the socket is there now, and it is the nearer."""
    path = tmp_path / "remote.sock"
    probed: list[RemoteAddress] = []

    def probe(address: RemoteAddress) -> None:
        probed.append(address)
        path.touch()  # the remote came up between the listing and this probe

    monkeypatch.setattr(docker_pool, "probe", probe)
    chosen = _launcher(path)._healthy("cid", 0)
    assert chosen == RemoteAddress("", 0, str(path)), probed
    assert probed == [TCP, chosen]


def test_the_port_that_answered_is_kept_when_the_socket_does_not(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "remote.sock"
    path.touch()

    def probe(address: RemoteAddress) -> None:
        if address.path is not None:
            raise WireError("socket: connection refused")

    monkeypatch.setattr(docker_pool, "probe", probe)
    assert _launcher(path)._healthy("cid", 0) == TCP
    monkeypatch.setattr(docker_pool, "probe", lambda address: None)
    assert _launcher(tmp_path / "absent.sock")._healthy("cid", 0) == TCP
