"""A robot API client that floods its port with small valid requests (a hostile or broken robot
controller): after the handshake it writes frames of one position target without pause, as fast
as the server takes them, and reads and throws away whatever the server sends."""

from __future__ import annotations

import socket
import threading
import time

from contracts.robot_api import messages_pb2 as pb

FRAMES_PER_WRITE = 4096


def flood_frames(count: int = FRAMES_PER_WRITE) -> bytes:
    """``count`` framed ``ActuatorRequests`` of one position target each (19 bytes a frame)."""
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="Neck", position=0.5)
    body: bytes = request.SerializeToString()
    return (len(body).to_bytes(4, "big") + body) * count


def _drain(sock: socket.socket, stop: threading.Event) -> None:
    while not stop.is_set():
        try:
            if not sock.recv(1 << 16):
                return
        except TimeoutError:
            continue
        except OSError:
            return


def flood(port: int, stop: threading.Event, sent: list[int], host: str = "127.0.0.1") -> None:
    """Flood ``host:port`` until ``stop`` is set; ``sent[0]`` counts the frames written."""
    blob = flood_frames()
    deadline = time.monotonic() + 30.0  # the simulator may listen only after seconds
    while True:
        try:
            sock = socket.create_connection((host, port), timeout=5)
            break
        except ConnectionRefusedError:
            if time.monotonic() > deadline or stop.is_set():
                raise
            time.sleep(0.05)
    with sock:
        greeting = b""
        while len(greeting) < 8:
            chunk = sock.recv(8 - len(greeting))
            if not chunk:
                return
            greeting += chunk
        if greeting != b"Welcome\0":
            return
        sock.settimeout(0.2)
        reader = threading.Thread(target=_drain, args=(sock, stop), daemon=True)
        reader.start()
        view, offset = memoryview(blob), 0
        while not stop.is_set():
            try:
                offset += sock.send(view[offset:])
            except TimeoutError:
                continue  # the server reads no faster: try again, from where it stopped
            except OSError:
                break
            if offset == len(blob):
                offset = 0
                sent[0] += FRAMES_PER_WRITE
        stop.set()
        reader.join(timeout=5)


__all__ = ["flood", "flood_frames"]


if __name__ == "__main__":  # python -m testkit.flood_client PORT: flood until killed
    import sys

    flood(int(sys.argv[1]), threading.Event(), [0])
