"""A registry that answers a byte at a time (a tarpit) is cut off at each request's deadline,
whole answer included, and the pre-flight's image check fails on it instead of waiting."""

from __future__ import annotations

import socket
import threading
import time
from collections.abc import Iterator

import pytest

from orchestrator.registry.client import RegistryClient, RegistryError


class Tarpit:
    """Accepts connections and sends an HTTP answer one byte every ``every_s`` seconds."""

    ANSWER = (b"HTTP/1.1 200 OK\r\nContent-Type: application/json\r\nContent-Length: 100000\r\n"
              b"\r\n" + b" " * 100_000)

    def __init__(self, every_s: float) -> None:
        self.every_s = every_s
        self.server = socket.create_server(("127.0.0.1", 0))
        self.port = self.server.getsockname()[1]
        self.stopped = threading.Event()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        while not self.stopped.is_set():
            try:
                conn, _ = self.server.accept()
            except OSError:
                return
            threading.Thread(target=self._drip, args=(conn,), daemon=True).start()

    def _drip(self, conn: socket.socket) -> None:
        with conn:
            try:
                conn.recv(65536)
                for byte in self.ANSWER:
                    if self.stopped.is_set():
                        return
                    conn.sendall(bytes([byte]))
                    time.sleep(self.every_s)
            except OSError:
                return

    def close(self) -> None:
        self.stopped.set()
        self.server.close()


@pytest.fixture(params=["headers", "body"])
def tarpit(request: pytest.FixtureRequest) -> Iterator[Tarpit]:
    made = Tarpit(every_s=0.05 if request.param == "body" else 0.3)
    if request.param == "body":  # the headers arrive at once, the body drips
        head = made.ANSWER.index(b"\r\n\r\n") + 4

        def drip(conn: socket.socket) -> None:
            with conn:
                try:
                    conn.recv(65536)
                    conn.sendall(made.ANSWER[:head])
                    for byte in made.ANSWER[head:]:
                        if made.stopped.is_set():
                            return
                        conn.sendall(bytes([byte]))
                        time.sleep(made.every_s)
                except OSError:
                    return

        made._drip = drip  # type: ignore[method-assign]
    yield made
    made.close()


def test_a_dripping_registry_is_cut_at_the_request_deadline(tarpit: Tarpit) -> None:
    client = RegistryClient(f"http://127.0.0.1:{tarpit.port}", deadline_s=1.5)
    started = time.monotonic()
    with pytest.raises(RegistryError) as failed:
        client.tags("team/robot")  # each byte comes well within the socket timeout
    elapsed = time.monotonic() - started
    assert failed.value.kind == "deadline", failed.value
    assert not failed.value.transient  # not retried: four more deadlines would follow
    assert elapsed < 1.5 + 1.0, elapsed
