"""The Docker launcher of remotes chooses the nearest address a remote answers on (no engine:
its container side is replaced; tests/integration/envs runs it on a real one)."""

from __future__ import annotations

from pathlib import Path

import pytest

import envs.docker_pool as docker_pool
from contracts import process
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


def test_a_container_removed_while_it_starts_is_a_start_failure_naming_it() -> None:
    """Someone removes the container between the diagnosis and the listing of its addresses:
    the start fails with the cause, not an engine error from deep inside."""
    import docker.errors

    from envs.errors import RemoteStartFailed

    launcher = object.__new__(DockerLauncher)
    launcher.sockets = {}
    launcher.health_timeout_s = 5.0
    launcher.diagnose = lambda index: None  # type: ignore[method-assign]

    def gone(cid: str) -> list[RemoteAddress]:
        raise docker.errors.NotFound("No such container: 0123456789abcdef")

    launcher._candidates = gone  # type: ignore[method-assign]
    with pytest.raises(RemoteStartFailed) as failed:
        launcher._healthy("0123456789abcdef", 0)
    assert failed.value.address == "0123456789ab"
    assert "removed while it started" in failed.value.reason


def _ended_process() -> tuple[int, str]:
    """A process of ours that ran and ended: its pid and start time."""
    import subprocess
    import sys

    child = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(30)"])
    start = process.start_time(child.pid)
    child.kill()
    child.wait()
    assert start is not None
    return child.pid, start


def test_an_owner_is_gone_only_where_this_process_can_see_it(
        monkeypatch: pytest.MonkeyPatch) -> None:
    import os
    import socket

    host, namespace = socket.gethostname(), process.pid_namespace()
    assert namespace  # /proc tells this process's pid namespace
    me = docker_pool._owner()
    assert me.split(":") == [host, namespace, str(os.getpid()),
                             process.start_time(os.getpid())]
    assert not docker_pool.owner_gone(me)

    pid, start = _ended_process()
    assert docker_pool.owner_gone(f"{host}:{namespace}:{pid}:{start}")  # ended here
    # a live pid with another start time: the pid was reused, the owner is gone
    assert docker_pool.owner_gone(f"{host}:{namespace}:{os.getpid()}:1")
    # the same ended pid seen from another pid namespace or host: cannot tell, so alive
    assert not docker_pool.owner_gone(f"{host}:1:{pid}:{start}")
    assert not docker_pool.owner_gone(f"elsewhere:{namespace}:{pid}:{start}")
    # labels of earlier versions (host:pid) and unreadable ones
    assert docker_pool.owner_gone(f"{host}:{pid}")
    assert not docker_pool.owner_gone(f"{host}:{os.getpid()}")
    for odd in ("", "garbage", f"{host}:{namespace}:x:{start}", f"{host}:{namespace}:{pid}:"):
        assert not docker_pool.owner_gone(odd), odd
    # where /proc cannot tell the namespace, nothing is judged gone
    assert not docker_pool.owner_gone(f"{host}::{pid}:{start}")
    monkeypatch.setattr(process, "pid_namespace", lambda: "")
    assert not docker_pool.owner_gone(f"{host}:{namespace}:{pid}:{start}")
