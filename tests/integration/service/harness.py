"""Serving the real app on 127.0.0.1 for tests (uvicorn in a thread), shared by the unit and
integration tests of the service."""

from __future__ import annotations

import socket
import threading
import time
from dataclasses import dataclass
from typing import Any

import httpx
import uvicorn

from hlvs.app import create_app
from service import Settings


def free_port() -> int:
    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


@dataclass
class Served:
    url: str
    settings: Settings
    server: uvicorn.Server
    thread: threading.Thread

    def client(self, token: str | None = None) -> httpx.Client:
        headers = {"Authorization": f"Bearer {token}"} if token else {}
        return httpx.Client(base_url=self.url, headers=headers, timeout=30)

    def stop(self) -> None:
        self.server.should_exit = True
        self.thread.join(timeout=30)


def serve(settings: Settings, *, start_worker: bool = False, port: int | None = None,
          **factory: Any) -> Served:
    """Start the app on ``port`` (default: a free loopback port); returns once it answers.
    ``factory``: keyword arguments of :func:`service.create_app` (``pool_factory``,
    ``preflight``)."""
    port = port or free_port()
    app = create_app(settings, start_worker=start_worker, **factory)
    config = uvicorn.Config(app, host="127.0.0.1", port=port, log_level="warning",
                            lifespan="on")
    server = uvicorn.Server(config)
    exits: list[int | str | None] = []

    def run() -> None:
        try:
            server.run()
        except SystemExit as exc:  # uvicorn's way of saying the app did not start
            exits.append(exc.code)

    thread = threading.Thread(target=run, name=f"service-{port}", daemon=True)
    thread.start()
    url = f"http://127.0.0.1:{port}"
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if server.started:
            return Served(url=url, settings=settings, server=server, thread=thread)
        if not thread.is_alive():
            break
        time.sleep(0.02)
    told = f" (uvicorn exited with {exits[0]})" if exits else ""
    raise RuntimeError(f"the service did not start on {url}{told}")
