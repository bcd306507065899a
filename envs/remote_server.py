"""``python -m envs remote --port 7700 [--unix PATH]`` (the simulator image started with
``remote``): serve learning sessions over the remote protocol (:mod:`envs.wire`) on a TCP port
and optionally a Unix socket, one client at a time.

The session runs in this process exactly as in-process (:class:`envs.session.LocalSession`), so
an episode over a remote equals the same seeded episode in-process. A second client while one is
served is refused (``Refused\\0``). Exit codes: 0 on SIGTERM / SIGINT, 3 when the port cannot be
bound.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import signal
import socket
import sys
import threading
from types import FrameType
from typing import cast

from envs.errors import EnvError
from envs.frame import Frame
from envs.session import LocalSession
from envs.session_spec import ResetRequest, SessionSpec
from envs.wire import (
    REFUSED,
    TAG_ACTUATORS,
    TAG_SENSORS,
    TAG_TRAINER,
    TAG_TRUTH,
    WELCOME,
    FrameReader,
    ResetWire,
    TrainerMessage,
    WireError,
    decode_targets,
    encode_sensors,
    encode_truth,
    send_frames,
    send_json,
)

log = logging.getLogger(__name__)
TRAINER_OPS = ("place_ball", "place_robot", "set_game_state", "drop_ball")


class RemoteServer:
    """Serves on a TCP port and, with ``unix_path``, also on a Unix socket (bound first: when
    the port answers, the socket does too); one client at a time over both."""

    def __init__(self, *, host: str, port: int, unix_path: str | None = None) -> None:
        self.listeners: list[socket.socket] = []
        if unix_path is not None:
            if os.path.exists(unix_path):
                os.unlink(unix_path)
            unix = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
            unix.bind(unix_path)
            os.chmod(unix_path, 0o666)  # like a port on 127.0.0.1: any local user may connect
            unix.listen()
            self.listeners.append(unix)
        self.listener = socket.create_server((host, port), reuse_port=False)
        self.listeners.append(self.listener)
        self.port = int(self.listener.getsockname()[1])
        self.busy = threading.Lock()
        self.stopping = threading.Event()

    def serve_forever(self) -> None:
        for extra in self.listeners[:-1]:
            threading.Thread(target=self._accept, args=(extra,), daemon=True).start()
        self._accept(self.listener)

    def _accept(self, listener: socket.socket) -> None:
        listener.settimeout(0.5)
        while not self.stopping.is_set():
            try:
                conn, peer = listener.accept()
            except TimeoutError:
                continue
            except OSError:
                break
            where = f"{peer[0]}:{peer[1]}" if isinstance(peer, tuple) else "unix socket"
            if not self.busy.acquire(blocking=False):
                log.info("refused %s: a client is being served", where)
                _refuse(conn)
                continue
            threading.Thread(target=self._serve, args=(conn, where), daemon=True).start()

    def close(self) -> None:
        self.stopping.set()
        for listener in self.listeners:
            listener.close()

    def _serve(self, conn: socket.socket, where: str) -> None:
        log.info("client %s connected", where)
        session: LocalSession | None = None
        compact = False  # the client asked for F frames (see envs.wire)
        released = False
        try:
            if conn.family != socket.AF_UNIX:
                conn.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            conn.sendall(WELCOME)
            reader = FrameReader(conn)
            while True:
                tag, payload = reader.read()
                if tag == TAG_ACTUATORS:
                    if session is None:
                        send_json(conn, _error("EnvStateError", "open and reset first"))
                        continue
                    _reply_frame(conn, session.step(decode_targets(payload)), compact)
                    continue
                if tag != TAG_TRAINER:
                    raise WireError(f"unexpected frame tag {tag!r}")
                request: TrainerMessage = json.loads(payload)
                op = request.get("op")
                if op == "close":  # free the remote before answering: the next client may come
                    if session is not None:
                        session.close()
                        session = None
                    self.busy.release()
                    released = True
                    send_json(conn, {"ok": True})
                    break
                if op == "open":
                    compact = bool(request.get("compact"))
                session = self._trainer(conn, session, op, request, compact)
        except (WireError, OSError, ValueError) as exc:
            log.info("client %s gone: %s", where, exc)
        finally:
            if session is not None:
                session.close()
            conn.close()
            if not released:
                self.busy.release()
            log.info("client %s done", where)

    def _trainer(
        self, conn: socket.socket, session: LocalSession | None, op: str | None,
        request: TrainerMessage,
        compact: bool,
    ) -> LocalSession | None:  # fmt: skip
        try:
            if op == "health":
                send_json(conn, {"ok": True, "pid": os.getpid()})
            elif op == "open":
                if session is not None:
                    session.close()
                session = LocalSession(SessionSpec.from_dict(dict(request.get("spec") or {})))
                send_json(conn, {"ok": True, "compact": compact})
            elif op == "reset":
                if session is None:
                    raise _NotOpen()
                r: ResetWire = request.get("request") or {}
                pose, ball = r.get("learner_pose"), r.get("ball_xy")  # as RemoteSession sends
                reset = ResetRequest(
                    seed=int(r["seed"]),
                    learner_pose=cast("tuple[float, float, float]", tuple(pose)) if pose else None,
                    ball_xy=cast("tuple[float, float]", tuple(ball)) if ball else None,
                )
                _reply_frame(conn, session.reset(reset), compact)
            elif op in TRAINER_OPS:
                if session is None:
                    raise _NotOpen()
                getattr(session, op)(*request.get("args", []))
                send_json(conn, {"ok": True})
            else:
                send_json(conn, _error("EnvConfigError", f"unknown op {op!r}"))
        except _NotOpen:
            send_json(conn, _error("EnvStateError", "send 'open' with the session spec first"))
        except (EnvError, KeyError, TypeError, ValueError) as exc:
            send_json(conn, _error(type(exc).__name__, str(exc)))
        return session


class _NotOpen(Exception):
    pass


def _error(kind: str, message: str) -> TrainerMessage:
    return {"ok": False, "error": kind, "message": message}


def _reply_frame(conn: socket.socket, frame: Frame, compact: bool) -> None:
    sensors = encode_sensors(frame.sim_time_ms, frame.sensors, frame.image)
    if compact and frame.perception is None and frame.game is None and not frame.events:
        send_frames(conn, [(TAG_SENSORS, sensors), (TAG_TRUTH, encode_truth(frame.truth))])
        return
    answer = json.dumps({"ok": True, "frame": frame.to_wire()}).encode()
    send_frames(conn, [(TAG_SENSORS, sensors), (TAG_TRAINER, answer)])


def _refuse(conn: socket.socket) -> None:
    try:
        conn.sendall(REFUSED)
    except OSError:
        pass
    conn.close()


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(
        prog=f"{os.environ.get('HLVS_PROG', 'python -m simulator')} remote",
        description="serve learning sessions (robot API messages + trainer channel) on a port",
    )
    parser.add_argument("--host", default="0.0.0.0", help="address to listen on")
    parser.add_argument("--port", type=int, default=7700, help="TCP port")
    parser.add_argument("--unix", default=None, help="also serve on this Unix socket path")
    parser.add_argument("--log-level", default="INFO", help="logging level")
    args = parser.parse_args(argv)
    if not os.environ.get("DISPLAY"):
        os.environ.setdefault("MUJOCO_GL", "osmesa")
        os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])
    logging.basicConfig(
        level=args.log_level.upper(), stream=sys.stderr,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )  # fmt: skip
    try:
        server = RemoteServer(host=args.host, port=args.port, unix_path=args.unix)
    except OSError as exc:
        log.error("cannot listen on %s:%d%s: %s", args.host, args.port,
                  f" and {args.unix}" if args.unix else "", exc)  # fmt: skip
        return 3

    def stop(signum: int, _frame: FrameType | None) -> None:
        log.info("%s: stopping", signal.Signals(signum).name)
        server.close()

    signal.signal(signal.SIGTERM, stop)
    signal.signal(signal.SIGINT, stop)
    log.info("learning sessions on %s:%d%s", args.host, server.port,
             f" and {args.unix}" if args.unix else "")  # fmt: skip
    server.serve_forever()
    return 0
