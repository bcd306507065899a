"""Remote simulators as containers on the local Docker engine (the only envs module that imports
``docker``).

Each remote is the simulator image started with ``remote --port 7700``, its port published on
127.0.0.1 at a port the engine picks, and with ``--unix`` on a Unix socket in a folder of the
pool's (under the system's temporary folder) mounted into the container. The pool connects to
that socket when it appears here (a local engine: about half the round trip of TCP over the
bridge), else to the container's bridge address, else to the published port. Containers carry
the project label, the role ``env-remote``, the pool id and the owner
(``host:pid-namespace:pid:start-time``): :meth:`DockerLauncher.close` removes a pool's
containers by label, and a new pool first removes the containers (and socket folders) of owners
that no longer run on this host (left by a killed process). An owner is judged gone only where
this process can see it: same host, same pid namespace (a pool in a container, or a job of a
cluster, sharing the engine may run in another, where its live pid looks free), and no process
of that pid with that start time (a reused pid is not the owner); a cluster job's remote is left
to its job's epilog. A remote is healthy once it greets and answers ``health``.
"""

from __future__ import annotations

import atexit
import logging
import os
import shutil
import socket
import tempfile
import time
import uuid
from pathlib import Path

import docker
import docker.errors

from contracts import process
from envs.errors import RemoteStartFailed
from envs.remote import RemoteAddress, probe
from envs.wire import WireError

log = logging.getLogger(__name__)

LABEL_PROJECT = "org.hlvs-runner"
LABEL_ROLE = "org.hlvs-runner.role"
LABEL_POOL = "org.hlvs-runner.env-pool"
LABEL_OWNER = "org.hlvs-runner.env-owner"
ROLE = "env-remote"
CONTAINER_PORT = 7700
SOCKET_DIR = "/run/hlvs-remote"  # in the container; a folder of the pool's on this machine
SOCKET_NAME = "remote.sock"
HEALTH_TIMEOUT_S = 60.0


def _owner() -> str:
    pid = os.getpid()
    start = process.start_time(pid) or ""
    return f"{socket.gethostname()}:{process.pid_namespace()}:{pid}:{start}"


def owner_gone(owner: str) -> bool:
    """True only when ``owner`` (a container's owner label) certainly no longer runs: it ran on
    this host, in this pid namespace, and no process has its pid and start time. An owner this
    process cannot see (another host, another pid namespace, an unreadable label) is alive."""
    parts = owner.split(":")
    if len(parts) == 2:  # host:pid, the label of earlier versions
        host, pid = parts
        return host == socket.gethostname() and pid.isdigit() and not _pid_alive(int(pid))
    if len(parts) != 4:
        return False
    host, namespace, pid, start = parts
    return pid.isdigit() and process.ended(hostname=host, namespace=namespace, pid=int(pid),
                                           start=start)


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def default_image() -> str:
    """``HLVS_SIMULATOR_IMAGE``, else the simulator image of this code (built if missing)."""
    name = os.environ.get("HLVS_SIMULATOR_IMAGE")
    if name:
        return name
    from orchestrator import ensure_image

    return ensure_image("simulator").reference


class DockerLauncher:
    def __init__(
        self,
        *,
        image: str | None = None,
        health_timeout_s: float = HEALTH_TIMEOUT_S,
        labels: dict[str, str] | None = None,
        publish_host: str = "127.0.0.1",
        unix: bool = True,
    ) -> None:
        try:
            self.client = docker.from_env(timeout=120)
            self.client.ping()
        except (docker.errors.DockerException, OSError) as exc:
            raise RemoteStartFailed(address="docker", reason=f"no Docker engine: {exc}") from exc
        self.image = image or default_image()
        self.pool_id = uuid.uuid4().hex[:10]
        self.health_timeout_s = health_timeout_s
        self.extra_labels = dict(labels or {})
        self.publish_host = publish_host
        # each remote also serves on a Unix socket in a folder of ours mounted into it
        self.socket_root = (
            Path(tempfile.mkdtemp(prefix=f"hlvs-env-{self.pool_id}-")) if unix else None
        )
        self.sockets: dict[str, str] = {}  # container id -> socket path on this machine
        self.containers: list[str] = []
        self._closed = False
        atexit.register(self.close)
        self._remove_orphans()

    def _labels(self) -> dict[str, str]:
        return {LABEL_PROJECT: "1", LABEL_ROLE: ROLE, LABEL_POOL: self.pool_id,
                LABEL_OWNER: _owner(), **self.extra_labels}  # fmt: skip

    def _remove_orphans(self) -> None:
        from orchestrator.engine import LABEL_SLURM_JOB

        for c in self.client.containers.list(all=True, ignore_removed=True,
                                            filters={"label": f"{LABEL_ROLE}={ROLE}"}):
            if LABEL_SLURM_JOB in c.labels:  # a cluster job's: its job's epilog removes it
                continue
            owner = c.labels.get(LABEL_OWNER, "")
            if owner_gone(owner):
                log.info("removing remote %s left by process %s (gone)", c.name, owner)
                self._remove(c.id)
                pool = c.labels.get(LABEL_POOL, "")
                for folder in Path(tempfile.gettempdir()).glob(f"hlvs-env-{pool}-*"):
                    shutil.rmtree(folder, ignore_errors=True)

    def start(self, count: int) -> list[RemoteAddress]:
        started = [self._run(i) for i in range(count)]
        return [self._healthy(cid, i) for i, cid in enumerate(started)]

    def _run(self, index: int) -> str:
        name = f"hlvs-env-{self.pool_id}-{index}-{uuid.uuid4().hex[:4]}"
        command = ["python3", "-m", "envs", "remote", "--port", str(CONTAINER_PORT)]
        volumes: dict[str, dict[str, str]] = {}
        folder = None
        if self.socket_root is not None:
            folder = self.socket_root / name
            folder.mkdir()
            volumes[str(folder)] = {"bind": SOCKET_DIR, "mode": "rw"}
            command += ["--unix", f"{SOCKET_DIR}/{SOCKET_NAME}"]
        try:
            container = self.client.containers.run(
                self.image,
                command=command,
                name=name,
                detach=True,
                labels=self._labels(),
                ports={f"{CONTAINER_PORT}/tcp": (self.publish_host, None)},
                environment={"LP_NUM_THREADS": "0"},
                volumes=volumes,
            )
        except docker.errors.DockerException as exc:
            raise RemoteStartFailed(address=name, reason=str(exc)) from exc
        cid = str(container.id)
        if folder is not None:
            self.sockets[cid] = str(folder / SOCKET_NAME)
        if index < len(self.containers):
            self.containers[index] = cid
        else:
            self.containers.append(cid)
        log.info("started remote %s (%s)", name, self.image)
        return cid

    def published_port(self, index: int) -> int | None:
        """The host port the engine published remote ``index``'s port on, if any."""
        settings = (
            self.client.containers.get(self.containers[index]).attrs.get("NetworkSettings") or {}
        )
        bound = (settings.get("Ports") or {}).get(f"{CONTAINER_PORT}/tcp") or []
        return int(bound[0]["HostPort"]) if bound else None

    def _candidates(self, cid: str) -> list[RemoteAddress]:
        """Where the remote answers: its Unix socket first (a local engine: the shortest round
        trip), then its bridge address (no userland proxy in the way, about three times the
        steps per second of the published port), then the published port on 127.0.0.1."""
        settings = self.client.containers.get(cid).attrs.get("NetworkSettings") or {}
        path = self.sockets.get(cid)
        out = [RemoteAddress("", 0, path)] if path and os.path.exists(path) else []
        out += [
            RemoteAddress(str(net["IPAddress"]), CONTAINER_PORT)
            for net in (settings.get("Networks") or {}).values()
            if net.get("IPAddress")
        ]
        bound = (settings.get("Ports") or {}).get(f"{CONTAINER_PORT}/tcp") or []
        if bound:
            out.append(RemoteAddress("127.0.0.1", int(bound[0]["HostPort"])))
        return out

    def _healthy(self, cid: str, index: int) -> RemoteAddress:
        deadline = time.monotonic() + self.health_timeout_s
        reason = "no answer"
        while time.monotonic() < deadline:
            cause = self.diagnose(index)
            if cause is not None:
                raise RemoteStartFailed(address=cid[:12], reason=cause)
            try:
                candidates = self._candidates(cid)
            except docker.errors.NotFound:  # between the diagnosis and the listing
                raise RemoteStartFailed(
                    address=cid[:12], reason="its container was removed while it started"
                ) from None
            for address in candidates:
                try:
                    probe(address)
                except (OSError, WireError) as exc:
                    reason = f"{address}: {exc}"
                    continue
                return self._nearest(cid, address)
            time.sleep(0.2)
        raise RemoteStartFailed(
            address=cid[:12], reason=f"not healthy after {self.health_timeout_s:g} s: {reason}"
        )

    def _nearest(self, cid: str, answered: RemoteAddress) -> RemoteAddress:
        """The remote's Unix socket when it has one, else ``answered``. The remote binds its
        socket before its port, so once the port answers the socket is there, even when it
        was not yet when the candidates were listed."""
        path = self.sockets.get(cid)
        if answered.path is not None or not path or not os.path.exists(path):
            return answered
        unix = RemoteAddress("", 0, path)
        try:
            probe(unix)
        except (OSError, WireError):
            return answered
        return unix

    def replace(self, index: int) -> RemoteAddress:
        old = self.containers[index]
        self._remove(old)
        self.sockets.pop(old, None)
        return self._healthy(self._run(index), index)

    def diagnose(self, index: int) -> str | None:
        """Why remote ``index`` is not running (exit code, OOM, last log lines), or None."""
        try:
            container = self.client.containers.get(self.containers[index])
        except docker.errors.NotFound:
            return "its container is gone (removed by someone)"
        except docker.errors.DockerException as exc:
            return f"the engine cannot tell: {exc}"
        state = container.attrs.get("State") or {}
        if state.get("Running"):
            return None
        logs = container.logs(tail=5).decode(errors="replace").strip().replace("\n", " | ")
        oom = " (out of memory)" if state.get("OOMKilled") else ""
        return f"container exited with code {state.get('ExitCode')}{oom}; last log lines: {logs}"

    def _remove(self, cid: str) -> None:
        try:
            self.client.containers.get(cid).remove(force=True)
        except docker.errors.NotFound:
            pass
        except docker.errors.DockerException as exc:
            log.warning("could not remove remote %s: %s", cid[:12], exc)

    def stop(self, grace_s: float) -> None:
        """SIGTERM to every remote, SIGKILL after ``grace_s`` (then :meth:`close` removes)."""
        for cid in self.containers:
            try:
                self.client.containers.get(cid).stop(timeout=max(0, round(grace_s)))
            except docker.errors.NotFound:
                pass
            except docker.errors.DockerException as exc:
                log.warning("could not stop remote %s: %s", cid[:12], exc)

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        atexit.unregister(self.close)
        found = self.client.containers.list(  # one removed meanwhile is not an error
            all=True, ignore_removed=True, filters={"label": f"{LABEL_POOL}={self.pool_id}"}
        )
        for container in found:
            self._remove(str(container.id))
        log.info("removed %d remote(s) of pool %s", len(found), self.pool_id)
        self.client.close()
        if self.socket_root is not None:
            shutil.rmtree(self.socket_root, ignore_errors=True)
