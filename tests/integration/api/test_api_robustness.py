"""A never-reading client, lockstep waiting and slowness, fuzzed bytes on the read path."""

from __future__ import annotations

import socket
import time

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contracts.match_spec import NetworkSpec
from contracts.robot_api import messages_pb2 as pb
from robot.client import RobotClient
from simulator.api import FakeDeviceWorld, LockstepSettings
from simulator.api.connection import Connection
from simulator.api.devices import KID_MOTORS
from simulator.api.server import IoThreadFailed
from tests.integration.api.harness import BLUE1, RED1, RED2, running_server, wait_until


def _client(port: int) -> RobotClient:
    return RobotClient("127.0.0.1", port, retries=3, retry_interval_s=0.1).connect()


def test_never_reading_client_does_not_stall_the_others() -> None:
    network = NetworkSpec(api_bind_host="127.0.0.1", send_queue_messages=8)
    world = FakeDeviceWorld((RED1, RED2, BLUE1))  # thousands of steps per second
    with running_server(network=network, pause_s=0.0, world=world) as (driver, ports):
        stalled = socket.create_connection(("127.0.0.1", ports[RED2]), timeout=5)
        stalled.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
        assert stalled.recv(8) == b"Welcome\0"
        # every sensor at every step, then it never reads: large measurements fill the
        # kernel's buffers within seconds, then its own queue
        enable = pb.ActuatorRequests()
        for name in [f"{m}S" for m in KID_MOTORS] + ["Accelerometer", "Gyro"]:
            enable.sensor_time_steps.add(name=name, timeStep=8)
        payload = enable.SerializeToString()
        stalled.sendall(len(payload).to_bytes(4, "big") + payload)
        with _client(ports[RED1]) as reader:
            reader.enable_many({f"{m}S": 8 for m in ("Neck", "Head", "PelvL", "PelvR")})
            steps_before = driver.steps
            wait_until(lambda: driver.server.statistics()["red-2"]["dropped_out"] > 0, 30)
            first = reader.receive(timeout=5).time
            for _ in range(50):
                last = reader.receive(timeout=5).time
            assert last == first + 50 * 8
            assert driver.steps > steps_before + 50
        stalled.close()


# pipelined=True: the same waits with the clients' socket I/O on the I/O thread
@pytest.mark.parametrize("pipelined", [False, True], ids=["step-thread-io", "io-thread"])
def test_lockstep_waits_for_each_client_then_marks_a_silent_one_slow(pipelined: bool) -> None:
    lockstep = LockstepSettings(deadline_s=0.02, time_bank_s=0.5, pipelined=pipelined)
    with running_server(lockstep=lockstep, pause_s=0.0, hold=True) as (driver, ports):
        with _client(ports[RED1]) as client:
            client.enable("NeckS", 8)
            wait_until(lambda: driver.server.connected())
            driver.max_steps = None
            for _ in range(30):  # answer every measurement: exactly one step per answer
                msg = client.receive(timeout=5)
                client.set_positions({"Neck": msg.time / 1000.0})
            client.receive(timeout=5)  # the step after the last answer
            time.sleep(0.01)
            steps = driver.steps
            time.sleep(0.05)
            assert driver.steps == steps  # not answered yet: within deadline + bank
            wait_until(lambda: driver.server.statistics()["red-1"]["slow_periods"] == 1, 5)
            stats = driver.server.statistics()["red-1"]
            assert stats["missed_deadlines"] >= 1
            wait_until(lambda: driver.steps > steps + 20)  # goes on without the slow client


@pytest.mark.parametrize("pipelined", [False, True], ids=["step-thread-io", "io-thread"])
def test_lockstep_is_deterministic_with_a_deterministic_client(pipelined: bool) -> None:
    def run() -> list[tuple[int, float]]:
        lockstep = LockstepSettings(deadline_s=1.0, time_bank_s=5.0, pipelined=pipelined)
        with running_server(lockstep=lockstep, pause_s=0.0, hold=True) as (driver, ports):
            with _client(ports[RED1]) as client:
                client.enable("NeckS", 8)
                wait_until(lambda: driver.server.connected())
                driver.max_steps = 60
                trace = []
                for _ in range(59):
                    msg = client.receive(timeout=5)
                    value = msg.position_sensors[0].value if msg.position_sensors else 0.0
                    trace.append((msg.time, round(value, 9)))
                    client.set_positions({"Neck": value + 0.01 * (msg.time % 24)})
                return trace

    assert run() == run()


@pytest.mark.parametrize("pipelined", [False, True], ids=["step-thread-io", "io-thread"])
def test_a_client_leaving_during_the_lockstep_wait_is_dropped_at_once(pipelined: bool) -> None:
    """The wait does not spend the deadline and time bank on a client that is gone (with the
    I/O thread: it finds the end of stream and wakes the waiting step thread)."""
    lockstep = LockstepSettings(deadline_s=5.0, time_bank_s=20.0, pipelined=pipelined)
    with running_server(lockstep=lockstep, pause_s=0.0, hold=True) as (driver, ports):
        assert (driver.server._sender is not None) is pipelined
        client = _client(ports[RED1])
        client.enable("NeckS", 8)
        wait_until(lambda: driver.server.connected())
        driver.max_steps = None
        for _ in range(5):
            msg = client.receive(timeout=5)
            client.set_positions({"Neck": msg.time / 1000.0})
        client.receive(timeout=5)  # the step waits for the answer to this one
        steps = driver.steps
        client.close()
        started = time.monotonic()
        wait_until(lambda: driver.steps > steps + 10, 3)
        assert time.monotonic() - started < 2.0  # far below the 5 s deadline
        reasons = driver.server.statistics()["red-1"]["disconnect_reasons"]
        assert reasons == ["client disconnected"]


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(chunks=st.lists(st.binary(min_size=1, max_size=64), min_size=1, max_size=6))
def test_arbitrary_bytes_never_break_the_server(chunks: list[bytes]) -> None:
    world = FakeDeviceWorld((RED1, BLUE1))
    with running_server(robots=(RED1, BLUE1), world=world) as (driver, ports):
        raw = socket.create_connection(("127.0.0.1", ports[RED1]), timeout=5)
        assert raw.recv(8) == b"Welcome\0"
        for chunk in chunks:
            try:
                raw.sendall(chunk)
            except OSError:
                break  # the server closed us: fine
        raw.close()
        with _client(ports[BLUE1]) as other:
            t0 = other.receive(timeout=5).time
            assert other.receive(timeout=5).time == t0 + 8
        assert driver.error is None


@pytest.mark.filterwarnings("error::pytest.PytestUnhandledThreadExceptionWarning")
def test_clients_coming_and_going_never_stop_the_others_measurements() -> None:
    """Async stepping, clients' I/O on the I/O thread: one robot's client connects and leaves
    a hundred times (sometimes with requests still unread, so the server sees a reset) while
    another reads on. Every drop closes a socket the I/O thread may be waiting on; the other
    robot's measurements keep coming, one per step (the thread once died of this, and every
    robot's measurements stopped; an exception in any thread fails the test)."""
    world = FakeDeviceWorld((RED1, RED2))
    with running_server(pause_s=0.0005, world=world) as (driver, ports):
        with _client(ports[RED1]) as reader:
            reader.enable("NeckS", 8)
            previous = reader.receive(timeout=5).time
            for k in range(100):
                leaving = _client(ports[RED2])
                leaving.enable("NeckS", 8)
                if k % 2:
                    leaving.set_positions({"Neck": 0.1})
                leaving.receive(timeout=5)
                leaving.close()
                wait_until(lambda n=k: len(driver.server.statistics()["red-2"]["disconnects"]) > n)
                for _ in range(3):
                    time_ms = reader.receive(timeout=5).time
                    assert time_ms > previous
                    previous = time_ms
            stats = driver.server.statistics()  # before the reader leaves too
        assert len(stats["red-2"]["connects"]) == 100
        assert stats["red-1"]["disconnects"] == []


@pytest.mark.filterwarnings("ignore::pytest.PytestUnhandledThreadExceptionWarning")
def test_a_failed_io_thread_stops_the_match_with_its_error(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """Should the I/O thread meet an unexpected error, the next step raises it (the simulator
    exits with the error in its log) instead of playing on with robots that hear nothing."""

    def broken(self: Connection, now: float) -> bool:
        raise RuntimeError("a bug in the I/O thread")

    monkeypatch.setattr(Connection, "read_threaded", broken)
    world = FakeDeviceWorld((RED1,))
    with pytest.raises(IoThreadFailed, match="a bug in the I/O thread"):  # the step's error
        with running_server(pause_s=0.001, world=world, robots=[RED1]) as (driver, ports):
            with _client(ports[RED1]) as client:
                client.enable("NeckS", 8)
                wait_until(lambda: driver.error is not None, 10)
            steps = driver.steps
            time.sleep(0.05)
            assert driver.steps == steps  # no step after it
