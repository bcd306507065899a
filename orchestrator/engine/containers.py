"""Docker adapter for the match: containers (and, through ``networks``, networks).

:class:`DockerRuntime` implements :class:`orchestrator.runtime.port.ContainerRuntime`.
Docker SDK errors become orchestrator errors in :func:`translate` and nowhere else.
"""

from __future__ import annotations

import contextlib
import logging
import tarfile
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import docker
import docker.errors
import docker.types
import requests.exceptions
import urllib3.exceptions

from orchestrator.engine import LABEL_MATCH, LABEL_PROJECT, engine_endpoint
from orchestrator.engine import networks as _networks
from orchestrator.errors import EngineLost, InfrastructureError
from orchestrator.runtime import ledger
from orchestrator.runtime.port import (
    ContainerRequest,
    ContainerState,
    NetworkInfo,
    NetworkRequest,
    ObjectNotFound,
    ProjectObject,
    StatsSample,
    SubnetInUse,
)

log = logging.getLogger(__name__)

_WAIT_TIMEOUTS = (requests.exceptions.ConnectionError, requests.exceptions.Timeout)
# the engine went away: its socket is gone or refuses, or it closed a connection mid-answer
_LOST = (requests.exceptions.ConnectionError, urllib3.exceptions.ProtocolError)


@contextlib.contextmanager
def translate(kind: str, name: str) -> Iterator[None]:
    """Turn Docker SDK and transport errors into :mod:`orchestrator.errors`; an engine that
    stopped answering is :class:`~orchestrator.errors.EngineLost`, naming the engine."""
    try:
        yield
    except docker.errors.NotFound as exc:
        raise ObjectNotFound(kind=kind, name=name, detail=str(exc.explanation or "")) from exc
    except docker.errors.APIError as exc:
        detail = exc.explanation or str(exc)
        raise InfrastructureError(f"Docker engine refused on {kind} {name}: {detail}") from exc
    except _LOST as exc:
        raise EngineLost(endpoint=engine_endpoint(), doing=f"{kind} {name}",
                         reason=str(exc)) from exc
    except (docker.errors.DockerException, requests.exceptions.RequestException, OSError) as exc:
        raise InfrastructureError(f"Docker engine failed on {kind} {name}: {exc}") from exc


class DockerRuntime:
    """The real container runtime on a Docker engine (``client`` from ``engine.connect()``)."""

    def __init__(self, client: docker.DockerClient) -> None:
        self._client = client

    # the engine -----------------------------------------------------------------------------
    def endpoint(self) -> str:
        """Where the engine is, for messages (``DOCKER_HOST`` or the local socket)."""
        return engine_endpoint()

    def answering(self) -> bool:
        """Whether the engine answers a ping now (False: stopped, restarting or crashed)."""
        try:
            return bool(self._client.ping())
        except (docker.errors.DockerException, requests.exceptions.RequestException,
                urllib3.exceptions.HTTPError, OSError):
            return False

    # networks -------------------------------------------------------------------------------
    def create_network(self, request: NetworkRequest) -> NetworkInfo:
        with translate("network", request.name), _intended("network", request.name):
            info = _networks.create_network(self._client, request)
        ledger.note(info.id)
        return info

    def remove_network(self, name: str) -> None:
        with translate("network", name):
            found = self._client.api.inspect_network(name)
            _networks.remove_network(self._client, name)
        ledger.forget(str(found.get("Id", "")))
        ledger.forget_name("network", str(found.get("Name", "")))

    # containers -----------------------------------------------------------------------------
    def create_container(self, request: ContainerRequest) -> str:
        host_config: dict[str, Any] = {
            "cap_drop": list(request.cap_drop) or None,
            "cap_add": list(request.cap_add) or None,
            "security_opt": list(request.security_opt) or None,
            "privileged": False,
            "binds": {
                str(m.source): {"bind": m.target, "mode": "ro" if m.read_only else "rw"}
                for m in request.mounts
            }
            or None,
            "nano_cpus": request.nano_cpus if request.cpu_period_us is None else None,
            "cpu_period": request.cpu_period_us if request.nano_cpus is not None else None,
            "cpu_quota": int(request.nano_cpus * request.cpu_period_us / 1e9)
            if request.nano_cpus is not None and request.cpu_period_us is not None else None,
            "mem_limit": request.mem_bytes,
            "memswap_limit": request.mem_bytes,
            "pids_limit": request.pids_limit,
            "read_only": request.read_only or None,
            "cpu_shares": request.cpu_shares,
            "cpuset_cpus": request.cpuset_cpus,
            "tmpfs": dict(request.tmpfs) or None,
            "cgroup_parent": request.cgroup_parent,
            "log_config": docker.types.LogConfig(type="json-file", config={
                "max-size": str(max(1, request.console_max_bytes // 2)), "max-file": "2"})
            if request.console_max_bytes is not None else None,
            "device_requests": [
                docker.types.DeviceRequest(
                    driver=d.driver, count=d.count, device_ids=list(d.device_ids),
                    capabilities=[list(c) for c in d.capabilities],
                )
                for d in request.device_requests
            ] or None,
            "network_mode": request.network_mode
            or (request.networks[0].network if request.networks else "none"),
            "runtime": request.runtime,
        }
        api = self._client.api
        networking = None
        if request.networks and not request.network_mode:
            first = request.networks[0]
            networking = api.create_networking_config(
                {
                    first.network: api.create_endpoint_config(
                        ipv4_address=first.ipv4_address, aliases=list(first.aliases) or None
                    )
                }
            )
        with translate("container", request.name), _intended("container", request.name):
            created = api.create_container(
                image=request.image,
                command=list(request.command) if request.command is not None else None,
                entrypoint=list(request.entrypoint) if request.entrypoint is not None else None,
                environment=dict(request.environment),
                labels=dict(request.labels),
                name=request.name,
                hostname=request.hostname,
                working_dir=request.working_dir,
                host_config=api.create_host_config(
                    **{k: v for k, v in host_config.items() if v is not None}
                ),
                networking_config=networking,
            )
            container_id = str(created["Id"])
            ledger.note(container_id)
            for extra in request.networks[1:]:
                api.connect_container_to_network(
                    container_id,
                    extra.network,
                    ipv4_address=extra.ipv4_address,
                    aliases=list(extra.aliases) or None,
                )
        log.debug("created container %s (%s)", request.name, request.image)
        return container_id

    def start(self, container_id: str) -> None:
        with translate("container", container_id):
            self._client.api.start(container_id)

    def stop(self, container_id: str, *, timeout_s: float) -> None:
        with translate("container", container_id):
            self._client.api.stop(container_id, timeout=max(0, round(timeout_s)))

    def kill(self, container_id: str) -> None:
        with translate("container", container_id):
            try:
                self._client.api.kill(container_id)
            except docker.errors.APIError as exc:
                if exc.status_code != 409:  # 409: not running
                    raise

    def remove(self, container_id: str) -> None:
        with translate("container", container_id):
            found = self._client.api.inspect_container(container_id)
            self._client.api.remove_container(container_id, force=True, v=True)
        ledger.forget(str(found.get("Id", "")))
        ledger.forget_name("container", str(found.get("Name", "")).lstrip("/"))

    def inspect(self, container_id: str) -> ContainerState:
        with translate("container", container_id):
            data = self._client.api.inspect_container(container_id)
        state = data.get("State", {})
        status = str(state.get("Status", ""))
        ran = bool(state.get("StartedAt", "").strip("0-:TZ."))
        finished = status in ("exited", "dead") and ran
        return ContainerState(
            id=str(data["Id"]),
            name=str(data.get("Name", "")).lstrip("/"),
            status=status,
            running=bool(state.get("Running")),
            exit_code=int(state.get("ExitCode", 0)) if finished else None,
            oom_killed=bool(state.get("OOMKilled")),
            restart_count=int(data.get("RestartCount", 0)),
            pid=int(state.get("Pid", 0)),
            error=str(state.get("Error", "")),
            started_at=str(state.get("StartedAt", "")),
            finished_at=str(state.get("FinishedAt", "")),
        )

    def wait(self, container_id: str, *, timeout_s: float) -> int | None:
        """Exit code, or None when the container still runs after ``timeout_s``."""
        try:
            with translate("container", container_id):
                result = self._client.api.wait(container_id, timeout=timeout_s)
        except InfrastructureError as exc:
            if isinstance(exc.__cause__, _WAIT_TIMEOUTS):
                return None
            raise
        return int(result.get("StatusCode", -1))

    def stats_stream(self, container_id: str) -> Iterator[StatsSample]:
        """Samples about once a second until the container stops (or the engine does)."""
        with translate("container", container_id):
            try:
                for raw in self._client.api.stats(container_id, stream=True, decode=True):
                    sample = _sample(raw)
                    if sample is not None:
                        yield sample
            except ValueError as exc:  # the stream cut mid-chunk (urllib3 reads a bad length)
                raise InfrastructureError(
                    f"the stats of container {container_id} broke off: {exc}") from exc

    def save_logs(self, container_id: str, *, stdout: Path, stderr: Path,
                  max_bytes: int | None = None) -> tuple[str, ...]:
        """Write the container's stdout and stderr, each cut at ``max_bytes``; returns the
        streams that were cut ("stdout", "stderr")."""
        cut: list[str] = []
        with translate("container", container_id):
            for path, out, err in ((stdout, True, False), (stderr, False, True)):
                path.parent.mkdir(parents=True, exist_ok=True)
                written = 0
                stream = self._client.api.logs(
                    container_id, stdout=out, stderr=err, stream=True, follow=False)
                try:
                    with path.open("wb") as handle:
                        for chunk in stream:
                            if max_bytes is not None and written + len(chunk) > max_bytes:
                                handle.write(chunk[:max_bytes - written])
                                cut.append("stdout" if out else "stderr")
                                break
                            handle.write(chunk)
                            written += len(chunk)
                finally:
                    close = getattr(stream, "close", None)
                    if callable(close):
                        close()
        return tuple(cut)

    def copy_out(self, container_id: str, path: str, destination: Path) -> None:
        """Copy ``path`` (a file or a folder) out of the container into ``destination``."""
        destination.mkdir(parents=True, exist_ok=True)
        with translate("container", f"{container_id}:{path}"):
            stream, _ = self._client.api.get_archive(container_id, path)
            with tempfile.TemporaryFile() as buffer:
                for chunk in stream:
                    buffer.write(chunk)
                buffer.seek(0)
                with tarfile.open(fileobj=buffer) as archive:
                    archive.extractall(destination, filter="data")

    def image_digest(self, image: str) -> str | None:
        """The image id (``sha256:...``) when the image is present locally, else None."""
        try:
            with translate("image", image):
                data = self._client.api.inspect_image(image)
        except ObjectNotFound:
            return None
        digests = data.get("RepoDigests") or []
        return str(digests[0]) if digests else str(data["Id"])

    def image_launch(self, image: str) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """The image's entry point and command (each empty when it has none)."""
        with translate("image", image):
            config = self._client.api.inspect_image(image).get("Config") or {}
        return tuple(config.get("Entrypoint") or ()), tuple(config.get("Cmd") or ())

    def list_project(self, *, match_id: str | None = None) -> list[ProjectObject]:
        labels = [f"{LABEL_PROJECT}=1"]
        if match_id is not None:
            labels.append(f"{LABEL_MATCH}={match_id}")
        found: list[ProjectObject] = []
        with translate("containers", "labelled " + ",".join(labels)):
            for c in self._client.api.containers(all=True, filters={"label": labels}):
                name = (c.get("Names") or ["/?"])[0].lstrip("/")
                found.append(
                    ProjectObject(
                        kind="container", id=str(c["Id"]), name=name, labels=c["Labels"] or {},
                        created=ledger.created(str(c["Id"]))
                        or ledger.intended("container", name),
                    )
                )
            for n in self._client.api.networks(filters={"label": labels}):
                found.append(
                    ProjectObject(
                        kind="network", id=str(n["Id"]), name=str(n["Name"]),
                        labels=n.get("Labels") or {},
                        created=ledger.created(str(n["Id"]))
                        or ledger.intended("network", str(n["Name"])),
                    )
                )
        return found


@contextlib.contextmanager
def _intended(kind: str, name: str) -> Iterator[None]:
    """The name of an object about to be created in the ledger (see
    :mod:`orchestrator.runtime.ledger`) for as long as the engine may hold it: kept when the
    request succeeds or ends without an answer from the engine, dropped when the engine
    refuses it (unless an earlier request of ours made the name already)."""
    earlier = ledger.intended(kind, name)
    ledger.intend(kind, name)
    try:
        yield
    except (docker.errors.APIError, SubnetInUse):  # answered: the engine made nothing
        if not earlier:
            ledger.forget_name(kind, name)
        raise


def _sample(raw: dict[str, Any]) -> StatsSample | None:
    """One sample of the engine's stats stream, or None where it measured nothing: a zero
    read time (the container is not running) or no memory figures (its cgroup was not
    there to read, as while it starts or stops on a loaded machine)."""
    cpu = raw.get("cpu_stats", {})
    pre = raw.get("precpu_stats", {})
    mem = raw.get("memory_stats", {})
    try:
        total = cpu["cpu_usage"]["total_usage"] - pre["cpu_usage"]["total_usage"]
        system = cpu["system_cpu_usage"] - pre["system_cpu_usage"]
        online = cpu.get("online_cpus") or len(cpu["cpu_usage"].get("percpu_usage") or [1])
    except (KeyError, TypeError):
        total, system, online = 0, 0, 1
    percent = (total / system) * online * 100.0 if system > 0 and total > 0 else 0.0
    usage = int(mem.get("max_usage") or mem.get("usage") or 0)
    if not raw.get("read", "").strip("0-:TZ.") or usage <= 0:
        return None
    return StatsSample(cpu_percent=percent, memory_bytes=usage)


__all__ = ["DockerRuntime", "translate"]
