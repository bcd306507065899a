"""A Docker engine of the test's own: a second ``dockerd`` with its own data, run folder,
pid file, socket and containerd (a namespace and a process of its own), so that a test may stop
and restart it without touching the shared engine other tests' containers run on. Needs root.

It must not fight the shared engine: a default bridge of its own, made here (``--bridge``; with
``--bridge=none`` an engine deletes the host's ``docker0`` as it starts, and the shared engine's
default network is gone until that engine restarts), and no iptables
rules of its own (``--iptables=false``: starting, an engine that writes iptables rules deletes
and remakes the DOCKER chains, the shared engine's too). Without its rules, traffic between the
containers of one of its bridges meets the host's ``FORWARD`` policy (the shared engine sets it
to DROP, and bridged traffic goes through iptables here): :meth:`OwnEngine.open_bridges` lets
it through for a match's bridges, as the shared engine's own rule does for its bridges."""

from __future__ import annotations

import contextlib
import os
import shutil
import signal
import subprocess
import tempfile
import time
from collections.abc import Iterable
from pathlib import Path

import docker
import docker.errors

COMMENT = "hlvs-test-own-engine"


class EngineDidNotStart(RuntimeError):
    pass


class OwnEngine:
    """``start()``, ``stop()`` (SIGTERM: the engine stops its containers, as a service
    manager's restart does), ``url`` (for ``DOCKER_HOST``), ``client()``, ``load(images)`` from
    the shared engine, ``open_bridges(names)``, ``close()`` (stopped and its folders removed)."""

    def __init__(self) -> None:
        # short paths: containerd's sockets live under the run folder (a socket path has a limit)
        self.folder = Path(tempfile.mkdtemp(prefix="hlvs-engine-", dir="/tmp"))
        self.log_path = self.folder / "dockerd.log"
        self.process: subprocess.Popen[bytes] | None = None
        self._rules: list[list[str]] = []
        self.bridge = f"hlvsown{os.getpid() % 100000}"  # at most 15 characters
        (self.folder / "daemon.json").write_text("{}")  # not the host's daemon.json

    @property
    def url(self) -> str:
        return f"unix://{self.folder / 'docker.sock'}"

    def _argv(self) -> list[str]:
        # containerd's namespaces are alphanumeric runs joined by single '.', '_' or '-': the
        # folder's random part may end in '_' ("hlvs-engine-fgycgyl_" was refused)
        name = self.folder.name.replace("_", "0")
        return [
            shutil.which("dockerd") or "dockerd",
            "--config-file", str(self.folder / "daemon.json"),
            "--data-root", str(self.folder / "data"),
            "--exec-root", str(self.folder / "run"),
            "--pidfile", str(self.folder / "docker.pid"),
            "-H", self.url,
            f"--bridge={self.bridge}", "--iptables=false", "--ip6tables=false",
            "--containerd-namespace", name, "--containerd-plugins-namespace", f"{name}-plugins",
            "--cgroup-parent", f"/{name}",
        ]

    def _make_bridge(self) -> None:
        """The engine's default bridge: a link with a private address of its own (the engine
        reads its subnet from the link's address)."""
        if subprocess.run(["ip", "link", "show", self.bridge], capture_output=True).returncode == 0:
            return
        used = subprocess.run(["ip", "-4", "route"], capture_output=True, text=True).stdout
        third = next((n for n in range(200, 250) if f"10.251.{n}." not in used), None)
        if third is None:
            raise EngineDidNotStart("no free 10.251.x.0/24 subnet for the engine's bridge")
        for argv in (["ip", "link", "add", self.bridge, "type", "bridge"],
                     ["ip", "addr", "add", f"10.251.{third}.1/24", "dev", self.bridge],
                     ["ip", "link", "set", self.bridge, "up"]):
            done = subprocess.run(argv, capture_output=True, text=True)
            if done.returncode != 0:
                raise EngineDidNotStart(f"{' '.join(argv)}: {done.stderr.strip()}")

    def start(self, timeout_s: float = 60.0) -> None:
        self._make_bridge()
        with self.log_path.open("ab") as log:
            self.process = subprocess.Popen(self._argv(), stdout=log, stderr=subprocess.STDOUT,
                                            start_new_session=True)
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            if self.process.poll() is not None:
                raise EngineDidNotStart(f"dockerd exited with code {self.process.returncode}: "
                                        f"{self.log_tail()}")
            with contextlib.suppress(docker.errors.DockerException, OSError), \
                    contextlib.closing(docker.DockerClient(base_url=self.url, timeout=5)) as c:
                if c.ping():
                    return
            time.sleep(0.3)
        raise EngineDidNotStart(f"dockerd did not answer within {timeout_s:.0f} s: "
                                f"{self.log_tail()}")

    def stop(self, timeout_s: float = 60.0) -> None:
        """A clean stop (SIGTERM): the engine stops every container (SIGTERM, then SIGKILL
        after their stop timeout of 10 s), then exits."""
        if self.process is None or self.process.poll() is not None:
            return
        self.process.send_signal(signal.SIGTERM)
        try:
            self.process.wait(timeout=timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait(timeout=30)

    def client(self) -> docker.DockerClient:
        return docker.DockerClient(base_url=self.url, timeout=120)

    def load(self, shared: docker.DockerClient, images: Iterable[str]) -> None:
        """The shared engine's ``images`` (with their tags) into this engine."""
        names = sorted(set(images))
        saving = subprocess.Popen(["docker", "save", *names], stdout=subprocess.PIPE,
                                  env={**os.environ, "DOCKER_HOST": "unix:///var/run/docker.sock"})
        loading = subprocess.run(["docker", "load", "-q"], stdin=saving.stdout,
                                 capture_output=True, text=True, timeout=600,
                                 env={**os.environ, "DOCKER_HOST": self.url})
        assert saving.stdout is not None
        saving.stdout.close()
        if saving.wait(timeout=600) != 0 or loading.returncode != 0:
            raise EngineDidNotStart(f"cannot load {names}: {loading.stderr[-500:]}")

    def open_bridges(self, names: Iterable[str]) -> None:
        for name in names:
            rule = ["FORWARD", "-i", name, "-o", name, "-m", "comment", "--comment", COMMENT,
                    "-j", "ACCEPT"]
            subprocess.run(["iptables", "-w", "5", "-I", *rule[:1], "1", *rule[1:]], check=True,
                           capture_output=True, timeout=30)
            self._rules.append(rule)

    def log_tail(self, chars: int = 1500) -> str:
        try:
            return self.log_path.read_text(errors="replace")[-chars:]
        except OSError:
            return ""

    def close(self) -> None:
        for rule in self._rules:
            subprocess.run(["iptables", "-w", "5", "-D", *rule], capture_output=True, timeout=30)
        self._rules.clear()
        try:
            if self.process is not None and self.process.poll() is None:
                # nothing of this engine outlives the test
                with contextlib.suppress(docker.errors.DockerException, OSError), \
                        contextlib.closing(self.client()) as client:
                    for container in client.containers.list(all=True):
                        container.remove(force=True)
        finally:
            self.stop()
            subprocess.run(["ip", "link", "delete", self.bridge], capture_output=True)
            shutil.rmtree(self.folder, ignore_errors=True)
