"""One :class:`robot.client.RobotClient` used from several threads, over a real socket: two
threads send large requests while a third polls ``receive`` with sub-millisecond timeouts (as
the stub robot drains its measurements). Every frame reaches the peer whole and in order per
thread, and no send fails: a receive's timeout is not the socket's, so a blocked ``sendall``
never inherits it, and frames are not interleaved."""

from __future__ import annotations

import socket
import threading
import time

from contracts.robot_api import messages_pb2 as pb
from robot.client import ReceiveTimeout, RobotClient
from simulator.api.framing import FrameDecoder

FRAMES_PER_THREAD = 200
MOTORS = 2000  # about 40 kB a frame, 16 MB in all: the client's send buffer fills up


def _request(sender: int, index: int) -> pb.ActuatorRequests:
    request = pb.ActuatorRequests()
    for k in range(MOTORS):
        request.motor_positions.add(name=f"s{sender}-m{k}", position=float(index))
    return request


def _peer(listener: socket.socket, frames: list[bytes], done: threading.Event) -> None:
    sock, _ = listener.accept()
    with sock:
        sock.sendall(b"Welcome\0")
        decoder = FrameDecoder()
        sock.settimeout(10.0)
        while len(frames) < 2 * FRAMES_PER_THREAD:
            time.sleep(0.001)  # a slow reader: the client's sends block on a full buffer
            data = sock.recv(65536)
            if not data:
                break
            frames.extend(decoder.feed(data))
    done.set()


def test_two_sending_threads_and_a_polling_receiver_share_one_client() -> None:
    listener = socket.socket()
    listener.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 32768)  # inherited by the peer
    listener.bind(("127.0.0.1", 0))
    listener.listen()
    frames: list[bytes] = []
    done = threading.Event()
    peer = threading.Thread(target=_peer, args=(listener, frames, done), daemon=True)
    peer.start()
    client = RobotClient("127.0.0.1", listener.getsockname()[1], retries=1).connect()
    errors: list[Exception] = []

    def send(sender: int) -> None:
        try:
            for index in range(FRAMES_PER_THREAD):
                client.send(_request(sender, index))
        except Exception as exc:  # noqa: BLE001 - reported by the assertion below
            errors.append(exc)

    senders = [threading.Thread(target=send, args=(s,)) for s in (0, 1)]
    for thread in senders:
        thread.start()
    try:
        while any(thread.is_alive() for thread in senders):
            try:
                client.receive(timeout=0.0005)
            except ReceiveTimeout:
                pass
        assert done.wait(30), f"the peer decoded {len(frames)} frames"
    finally:
        client.close()
        listener.close()
    assert not errors, errors
    seen: dict[int, list[int]] = {0: [], 1: []}
    for frame in frames:
        request = pb.ActuatorRequests.FromString(frame)
        first = request.motor_positions[0]
        sender = int(first.name[1])
        assert [m.name for m in request.motor_positions] == [
            f"s{sender}-m{k}" for k in range(MOTORS)
        ]
        seen[sender].append(int(first.position))
    assert seen == {0: list(range(FRAMES_PER_THREAD)), 1: list(range(FRAMES_PER_THREAD))}
