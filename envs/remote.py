"""Remote simulators behind environments: addresses and the client session (the pool that
starts them: :mod:`envs.remote_pool`).

``remotes="hlvs://host:port,host:port"`` names simulators someone started
(``docker run -p 7700:7700 hlvs-runner/simulator remote --port 7700``); ``remotes=N`` starts N
simulator containers on the local Docker engine (:mod:`envs.docker_pool`), health-checked,
labelled and removed at close; ``remotes="slurm:N"`` has a Slurm cluster run them, one job per
remote (:mod:`envs.slurm_pool`). A remote that dies during an episode raises
:class:`envs.errors.RemoteCrashed` with its cause (the container's exit code and last log lines,
or the socket error); the next ``reset()`` replaces a container the pool started.
"""

from __future__ import annotations

import json
import logging
import socket
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from envs.errors import (
    EnvConfigError,
    EnvStateError,
    RemoteCrashed,
    RemoteError,
    TrainerError,
)
from envs.frame import Frame
from envs.session_spec import ResetRequest, SessionSpec
from envs.wire import (
    REFUSED,
    TAG_ACTUATORS,
    TAG_SENSORS,
    TAG_TRAINER,
    TAG_TRUTH,
    WELCOME,
    FrameReader,
    TrainerMessage,
    WireError,
    decode_sensors,
    decode_truth,
    encode_targets,
    json_object,
    send_frame,
)

log = logging.getLogger(__name__)
SCHEME = "hlvs://"
UNIX_SCHEME = "hlvs+unix://"  # hlvs+unix:///path/to/remote.sock: a remote on this machine
CONNECT_TIMEOUT_S = 10.0
REPLY_TIMEOUT_S = 120.0


SLURM_SCHEME = "slurm:"
SLURM_KEYS = {"conf": str, "partition": str, "account": str, "dir": str, "lease": float,
              "timeout": float, "cpus": int}  # fmt: skip


@dataclass(frozen=True, slots=True)
class RemoteAddress:
    """A remote's TCP address, or with ``path`` its Unix socket (a remote on this machine:
    no TCP/IP stack, no bridge between the two ends; about half the round trip)."""

    host: str
    port: int
    path: str | None = None

    def __str__(self) -> str:
        if self.path is not None:
            return f"{UNIX_SCHEME}{self.path}"
        return f"{SCHEME}{self.host}:{self.port}"

    def connect(self, timeout_s: float) -> socket.socket:
        """A connected stream socket (raises OSError)."""
        if self.path is None:
            sock = socket.create_connection((self.host, self.port), timeout_s)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            return sock
        sock = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            sock.settimeout(timeout_s)
            sock.connect(self.path)
        except OSError:
            sock.close()
            raise
        return sock


def parse_remotes(text: str) -> list[RemoteAddress]:
    """``"hlvs://host:port,host:port"`` (the scheme may be given once, for each, or not at
    all); ``hlvs+unix:///absolute/path`` names a remote's Unix socket on this machine."""
    out = []
    for item in (part.strip() for part in text.split(",")):
        if not item:
            continue
        if item.startswith(UNIX_SCHEME):
            path = item[len(UNIX_SCHEME) :]
            if not path.startswith("/"):
                raise EnvConfigError(
                    field="remotes", value=item, expected="hlvs+unix:///absolute/path/to/socket"
                )
            out.append(RemoteAddress("", 0, path))
            continue
        bare = item[len(SCHEME) :] if item.startswith(SCHEME) else item
        host, sep, port = bare.rpartition(":")
        if "://" in bare or not sep or not host or not port.isdigit() or not 0 < int(port) < 65536:
            raise EnvConfigError(
                field="remotes", value=item, expected="hlvs://host:port[,host:port...]"
            )
        out.append(RemoteAddress(host, int(port)))
    if not out:
        raise EnvConfigError(field="remotes", value=text, expected="at least one hlvs://host:port")
    return out


def parse_slurm(text: str) -> tuple[int, dict[str, str | float | int]]:
    """``"slurm:N[?key=value&...]"``: how many remotes and the options (keys of
    :data:`SLURM_KEYS`: ``conf``, ``partition``, ``account``, ``dir``, ``lease`` and
    ``timeout`` in seconds, ``cpus``)."""
    expected = "slurm:N or slurm:N?key=value&... (keys: " + ", ".join(SLURM_KEYS) + ")"
    body = text[len(SLURM_SCHEME) :]
    count_text, _, query = body.partition("?")
    if not count_text.strip().isdigit() or int(count_text) < 1:
        raise EnvConfigError(field="remotes", value=text, expected=expected)
    options: dict[str, str | float | int] = {}
    for item in (part for part in query.split("&") if part):
        key, sep, value = item.partition("=")
        if key not in SLURM_KEYS or not sep or not value:
            raise EnvConfigError(field=f"remotes {text!r}: option", value=item,
                                 expected=expected, choices=list(SLURM_KEYS))  # fmt: skip
        kind = SLURM_KEYS[key]
        try:
            converted = kind(value)
        except ValueError:
            raise EnvConfigError(field=f"remotes {text!r}: {key}", value=value,
                                 expected=f"a {kind.__name__}") from None  # fmt: skip
        if not isinstance(converted, str) and converted <= 0:
            raise EnvConfigError(field=f"remotes {text!r}: {key}", value=value, expected="> 0")
        options[key] = converted
    return int(count_text), options


def probe(address: RemoteAddress) -> None:
    """Greeting and a ``health`` answer, then close (raises OSError / WireError)."""
    with address.connect(2.0) as sock:
        sock.settimeout(5.0)
        greeting = sock.recv(8)
        if greeting != WELCOME:
            raise WireError(f"greeting {greeting!r}")
        reader = FrameReader(sock)
        send_frame(sock, TAG_TRAINER, json.dumps({"op": "health"}).encode())
        if not reader.expect_json().get("ok"):
            raise WireError("health check failed")
        send_frame(sock, TAG_TRAINER, json.dumps({"op": "close"}).encode())
        reader.expect_json()


class RemoteSession:
    """A session on a remote simulator (the :class:`envs.base.Session` protocol)."""

    def __init__(
        self,
        address: RemoteAddress,
        spec: SessionSpec,
        *,
        diagnose: Callable[[], str | None] | None = None,
        connect_timeout_s: float = CONNECT_TIMEOUT_S,
    ) -> None:
        self.address = address
        self.spec = spec
        self.crashed = False
        self._diagnose = diagnose
        self._sock = self._connect(connect_timeout_s)
        self._reader = FrameReader(self._sock)
        opened = self._call({"op": "open", "spec": spec.to_dict(), "compact": True})
        self.compact = bool(opened.get("compact"))  # older remotes answer every step in JSON

    def _connect(self, timeout_s: float) -> socket.socket:
        where = str(self.address)
        try:
            sock = self.address.connect(timeout_s)
            greeting = b""
            while len(greeting) < 8:
                chunk = sock.recv(8 - len(greeting))
                if not chunk:
                    break
                greeting += chunk
        except OSError as exc:
            raise RemoteError(address=where, reason=f"cannot connect: {exc}") from exc
        if greeting == REFUSED:
            sock.close()
            raise RemoteError(address=where, reason="refused: it already serves another client")
        if greeting != WELCOME:
            sock.close()
            raise RemoteError(
                address=where, reason=f"not a remote simulator (greeting {greeting!r})"
            )
        sock.settimeout(REPLY_TIMEOUT_S)
        return sock

    # --- calls -------------------------------------------------------------------------------

    def _crash(self, exc: BaseException) -> RemoteCrashed:
        self.crashed = True
        cause = self._diagnose() if self._diagnose is not None else None
        return RemoteCrashed(address=str(self.address), cause=cause or f"connection lost ({exc})")

    def _check(self) -> None:
        if self.crashed:
            raise EnvStateError(operation="remote", reason=f"{self.address} crashed; reset()")

    def _call(self, request: TrainerMessage, *, operation: str = "") -> TrainerMessage:
        self._check()
        try:
            send_frame(self._sock, TAG_TRAINER, json.dumps(request).encode())
            answer = self._reader.expect_json()
        except (OSError, WireError) as exc:
            raise self._crash(exc) from exc
        return self._answer(answer, operation or str(request.get("op")))

    def _answer(self, answer: TrainerMessage, operation: str) -> TrainerMessage:
        if answer.get("ok"):
            return answer
        kind, message = str(answer.get("error")), str(answer.get("message"))
        if kind == "TrainerError":
            raise TrainerError(operation=operation, reason=message)
        raise RemoteError(address=str(self.address), reason=f"{operation}: {kind}: {message}")

    def _read_frame(self, operation: str) -> Frame:
        try:
            tag, payload = self._reader.read()
            if tag == TAG_TRAINER:  # an error instead of a frame
                self._answer(json.loads(payload), operation)
                raise WireError("a trainer answer without ok")
            if tag != TAG_SENSORS:
                raise WireError(f"unexpected frame tag {tag!r}")
            time_ms, sensors, image = decode_sensors(payload)
            tag, payload = self._reader.read()
            if tag == TAG_TRUTH and self.compact:
                truth = decode_truth(payload)
                return Frame(sim_time_ms=time_ms, sensors=sensors, truth=truth, image=image)
            if tag != TAG_TRAINER:
                raise WireError(f"unexpected frame tag {tag!r} after the sensors")
            answer = self._answer(json_object(payload), operation)
        except (OSError, WireError) as exc:
            raise self._crash(exc) from exc
        return Frame.from_wire(answer["frame"], sensors, image)

    # --- the Session protocol ----------------------------------------------------------------

    def reset(self, request: ResetRequest) -> Frame:
        self._check()
        wire = {
            "seed": request.seed,
            "learner_pose": list(request.learner_pose) if request.learner_pose else None,
            "ball_xy": list(request.ball_xy) if request.ball_xy else None,
        }
        try:
            send_frame(
                self._sock, TAG_TRAINER, json.dumps({"op": "reset", "request": wire}).encode()
            )
        except OSError as exc:
            raise self._crash(exc) from exc
        return self._read_frame("reset")

    def send_step(self, targets: npt.NDArray[np.float64] | Sequence[float]) -> None:
        """First half of :meth:`step` (a vector environment sends to every remote first)."""
        self._check()
        try:
            send_frame(self._sock, TAG_ACTUATORS, encode_targets(np.asarray(targets, np.float64)))
        except OSError as exc:
            raise self._crash(exc) from exc

    def receive_step(self) -> Frame:
        return self._read_frame("step")

    def step(self, targets: npt.NDArray[np.float64] | Sequence[float]) -> Frame:
        self.send_step(targets)
        return self.receive_step()

    def place_ball(self, x_m: float, y_m: float, vx_m_s: float = 0.0, vy_m_s: float = 0.0) -> None:
        self._call({"op": "place_ball", "args": [x_m, y_m, vx_m_s, vy_m_s]})

    def place_robot(self, color: str, number: int, x_m: float, y_m: float, yaw_rad: float) -> None:
        self._call({"op": "place_robot", "args": [color, number, x_m, y_m, yaw_rad]})

    def set_game_state(self, state: str) -> None:
        self._call({"op": "set_game_state", "args": [state]})

    def drop_ball(self, x_m: float = 0.0, y_m: float = 0.0) -> None:
        self._call({"op": "drop_ball", "args": [x_m, y_m]})

    def health(self) -> TrainerMessage:
        return self._call({"op": "health"})

    def close(self) -> None:
        if not self.crashed:
            try:
                send_frame(self._sock, TAG_TRAINER, b'{"op": "close"}')
                self._reader.expect_json()
            except (OSError, WireError):
                pass
        self._sock.close()
