"""GameController UDP (RGme out, RGrt in) and the team mirror, over real sockets on 127.x."""

from __future__ import annotations

import socket
import time
from collections.abc import Callable, Iterator
from pathlib import Path

import pytest

from contracts.gamecontroller import (
    ReturnData,
    ReturnMessage,
    decode_game_state,
    encode_return,
    with_packet_number,
)
from contracts.ids import RobotId, TeamColor
from referee import FakeClock, Referee, SystemClock, TeamMirror
from referee.config import NetworkConfig
from referee.net import GameControllerNetwork
from tests.unit.referee.referee_helpers import BLUE, RED, make_config, robot, snapshot


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def udp(host: str, port: int) -> socket.socket:
    sock = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    sock.bind((host, port))
    sock.settimeout(0.05)
    return sock


def wait_for(condition: Callable[[], bool], timeout_s: float = 5.0) -> bool:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if condition():
            return True
        time.sleep(0.01)
    return condition()


def receive_all(sock: socket.socket, duration_s: float) -> list[tuple[bytes, tuple[str, int]]]:
    got = []
    deadline = time.monotonic() + duration_s
    while time.monotonic() < deadline:
        try:
            got.append(sock.recvfrom(4096))
        except TimeoutError:
            continue
    return got


def receive_timed(
    sock: socket.socket, duration_s: float
) -> list[tuple[float, tuple[bytes, tuple[str, int]]]]:
    """Every datagram within ``duration_s``, with its arrival time (monotonic)."""
    got = []
    deadline = time.monotonic() + duration_s
    while time.monotonic() < deadline:
        try:
            datagram = sock.recvfrom(4096)
        except TimeoutError:
            continue
        got.append((time.monotonic(), datagram))
    return got


@pytest.fixture
def robots() -> Iterator[dict[str, socket.socket]]:
    port = free_port()
    sockets = {host: udp(host, port) for host in ("127.0.0.2", "127.0.0.3", "127.0.0.4")}
    yield sockets
    for sock in sockets.values():
        sock.close()


def test_rgme_sent_to_every_robot_at_a_fixed_2_hz_numbered_one_by_one(
    robots: dict[str, socket.socket],
) -> None:
    """League GameController (2024-master) ``controller/net/Sender.java``: the latest state is
    sent to every robot every 500 ms and ``packetNumber`` goes up by 1 per packet (mod 256); a
    state change sends nothing by itself."""
    port = robots["127.0.0.2"].getsockname()[1]
    net = GameControllerNetwork(
        bind_host="127.0.0.1", data_port=port, return_port=0, targets=list(robots),
        team_numbers={8: RED, 25: BLUE}, send_rate_hz=2.0, clock=SystemClock(),
    )
    ref = Referee(config=make_config(), clock=FakeClock())
    with net:
        net.publish(ref.packet(), state_changed=True)
        ref.step(snapshot(0, (robot(RED, 1, -1, 0),)))  # INITIAL -> READY (no wait)
        for _ in range(20):  # state changes and refreshes: not one packet more
            net.publish(ref.packet(), state_changed=True)
            time.sleep(0.01)
        got = receive_timed(robots["127.0.0.3"], 2.6)
    times = [at for at, _ in got]
    datas = [decode_game_state(raw, peer="test") for _, (raw, _) in got]
    assert 5 <= len(got) <= 7, len(got)  # 2.6 s at 2 Hz, room for a loaded machine
    assert [d.packet_number for d in datas] == list(
        range(datas[0].packet_number, datas[0].packet_number + len(datas))
    )
    gaps = [b - a for a, b in zip(times[1:], times[2:], strict=False)]  # the first was queued
    assert min(gaps) > 0.3, gaps  # never an extra packet between two ticks
    assert datas[-1].state == 1 and datas[-1].teams[0].team_number == 8  # READY, red on the left
    assert got[0][1][1][0] == "127.0.0.1"
    assert net.stats().datagrams_sent >= 3 * len(got)


def test_packet_numbers_wrap_at_256() -> None:
    """League GameController ``Sender.java``: ``packetNumber`` is a byte that wraps."""
    ref = Referee(config=make_config(), clock=FakeClock())
    raw = ref.packet()
    assert decode_game_state(with_packet_number(raw, 255)).packet_number == 255
    assert decode_game_state(with_packet_number(raw, 256)).packet_number == 0
    assert with_packet_number(raw, 3)[7:] == raw[7:]


def test_a_game_state_left_before_its_tick_still_gets_one_packet(
    robots: dict[str, socket.socket],
) -> None:
    """League referee (``referee.py``): it commands the next state only after it has seen the
    GameController broadcast FINISHED, so robots always get a FINISHED packet; ours lasts one
    step before the next period's INITIAL and goes out at its own tick, then INITIAL."""
    port = robots["127.0.0.2"].getsockname()[1]
    net = GameControllerNetwork(
        bind_host="127.0.0.1", data_port=port, return_port=0, targets=["127.0.0.2"],
        team_numbers={8: RED, 25: BLUE}, send_rate_hz=5.0, clock=SystemClock(),
    )
    ref = Referee(config=make_config(), clock=FakeClock())
    first, second = bytearray(ref.packet()), bytearray(ref.packet())
    first[9] = 1  # READY
    second[9] = 4  # FINISHED
    third = bytearray(ref.packet())
    third[9] = 0  # INITIAL
    with net:
        net.publish(bytes(first), state_changed=True)
        time.sleep(0.3)
        net.publish(bytes(second), state_changed=True)
        net.publish(bytes(third), state_changed=True)
        got = receive_all(robots["127.0.0.2"], 0.8)
    states = [decode_game_state(raw).state for raw, _ in got]
    assert 4 in states and states.index(4) < states.index(0), states
    assert states[states.index(4) + 1 :] == [0] * (len(states) - states.index(4) - 1), states


def test_rgrt_tracking_and_garbage() -> None:
    net = GameControllerNetwork(
        bind_host="127.0.0.1", data_port=free_port(), return_port=0, targets=[],
        team_numbers={8: RED, 25: BLUE}, send_rate_hz=2.0, clock=SystemClock(),
    )
    address = net.return_address
    with net, udp("127.0.0.5", 0) as sender:
        sender.sendto(encode_return(ReturnData(8, 2, ReturnMessage.ALIVE)), address)
        sender.sendto(encode_return(ReturnData(8, 2, ReturnMessage.GOALKEEPER)), address)
        sender.sendto(encode_return(ReturnData(25, 1, ReturnMessage.MAN_PENALISE)), address)
        sender.sendto(encode_return(ReturnData(25, 1, ReturnMessage.MAN_UNPENALISE)), address)
        sender.sendto(encode_return(ReturnData(25, 1, ReturnMessage.GAME_INTERRUPTION_READY)),
                      address)
        sender.sendto(encode_return(ReturnData(99, 1, ReturnMessage.ALIVE)), address)
        sender.sendto(b"hello robots", address)
        sender.sendto(b"RGrt\x07\x08\x01\x02", address)
        assert wait_for(lambda: net.stats().garbage == 2 and net.stats().unknown == 1)
        links = net.links()
        red2, blue1 = links[RobotId(RED, 2)], links[RobotId(BLUE, 1)]
        assert red2.messages == 2 and red2.goalkeeper_claim and red2.address == "127.0.0.5"
        assert red2.alive_s is not None
        assert (blue1.manual_penalise, blue1.manual_unpenalise) == (1, 1)
        assert blue1.ready_s is not None
        assert net.take_goalkeeper_claims() == [RobotId(RED, 2)]
        assert net.take_goalkeeper_claims() == []
        assert net.stats().returns_received == 5


def test_referee_network_end_to_end(tmp_path: Path, robots: dict[str, socket.socket]) -> None:
    """Referee.start_network: RGme to the robots, a goalkeeper claim reaches the GameController,
    the mirror relays team messages."""
    port = robots["127.0.0.2"].getsockname()[1]
    config = make_config(addresses={RED: ("127.0.0.2", "127.0.0.3"), BLUE: ("127.0.0.4",)})
    from dataclasses import replace

    config = replace(
        config,
        network=NetworkConfig(bind_host="127.0.0.1", gc_data_port=port, gc_return_port=0,
                              mirror_port=port),
    )
    ref = Referee(config=config, clock=SystemClock(), log_dir=tmp_path)
    ref.start_network()
    try:
        assert ref.network is not None and ref.mirror is not None
        got = receive_all(robots["127.0.0.4"], 0.3)
        assert got and decode_game_state(got[0][0]).teams[0].team_number == 8  # red on the left
        claim = encode_return(ReturnData(8, 2, ReturnMessage.GOALKEEPER))
        robots["127.0.0.3"].sendto(claim, ref.network.return_address)
        assert wait_for(lambda: RobotId(RED, 2) in ref.network.links())  # type: ignore[union-attr]
        ref.step(snapshot(0, (robot(RED, 1, -1, 0),)))
        assert ref.gc.goalkeeper(RED) == 2
        robots["127.0.0.2"].sendto(b"team talk", ref.mirror.address)
        deadline = time.monotonic() + 3
        relayed = None
        while relayed is None and time.monotonic() < deadline:
            for payload, source in receive_all(robots["127.0.0.3"], 0.1):
                if payload == b"team talk":
                    relayed = source
        assert relayed is not None and relayed[1] == port
    finally:
        ref.close()
    assert "packets sent" in (tmp_path / "gamecontroller.log").read_text()


def test_mirror_relays_to_teammates_only(tmp_path: Path) -> None:
    port = free_port()
    hosts = {RED: ["127.0.0.2", "127.0.0.3", "127.0.0.4"], BLUE: ["127.0.0.5", "127.0.0.6"]}
    sockets = {h: udp(h, port) for team in hosts.values() for h in team}
    stranger = udp("127.0.0.9", port)
    try:
        with TeamMirror(bind_host="127.0.0.1", port=port, teams=hosts, log_dir=tmp_path) as mirror:
            sockets["127.0.0.2"].sendto(b"x" * 1024, mirror.address)
            sockets["127.0.0.2"].sendto(b"y" * 1025, mirror.address)
            stranger.sendto(b"spy", mirror.address)
            sockets["127.0.0.6"].sendto(b"blue plan", mirror.address)
            assert wait_for(lambda: mirror.stats().received == 4)
            assert wait_for(lambda: mirror.stats().forwarded == 3)
            received = {h: [p for p, _ in receive_all(s, 0.3)] for h, s in sockets.items()}
            assert received["127.0.0.3"] == [b"x" * 1024] == received["127.0.0.4"]
            assert received["127.0.0.2"] == []  # not back to the sender
            assert received["127.0.0.5"] == [b"blue plan"] and received["127.0.0.6"] == []
            assert receive_all(stranger, 0.1) == []
            stats = mirror.stats()
            assert (stats.oversized, stats.unknown) == (1, 1)
        log = (tmp_path / "bouncing_log.txt").read_text()
        assert "Dropped 1025 bytes from red 127.0.0.2" in log
        assert "Ignored 3 bytes from unknown host 127.0.0.9" in log
        assert "Bounced 9 bytes from blue 127.0.0.6 to 1 teammates" in log
    finally:
        for sock in [*sockets.values(), stranger]:
            sock.close()


def test_mirror_ignores_address_listed_for_both_teams() -> None:
    port = free_port()
    hosts = {TeamColor.RED: ["127.0.0.1", "127.0.0.2"], TeamColor.BLUE: ["127.0.0.1", "127.0.0.3"]}
    with udp("127.0.0.3", port) as blue, udp("127.0.0.2", port) as red:
        with TeamMirror(bind_host="127.0.0.7", port=port, teams=hosts) as mirror:
            with udp("127.0.0.1", port) as shared:
                shared.sendto(b"who am i", mirror.address)
                assert wait_for(lambda: mirror.stats().unknown == 1)
            assert receive_all(blue, 0.1) == [] and receive_all(red, 0.1) == []


def test_rgrt_attributed_by_sender_address(tmp_path: Path,
                                           robots: dict[str, socket.socket]) -> None:
    """A red robot claiming blue's team number (or a teammate's number) changes nothing and is
    recorded as spoofing with its sender; its own claims are taken; the mirror records strangers."""
    port = robots["127.0.0.2"].getsockname()[1]
    config = make_config(addresses={RED: ("127.0.0.2", "127.0.0.3"), BLUE: ("127.0.0.4",)})
    from dataclasses import replace

    config = replace(
        config,
        network=NetworkConfig(bind_host="127.0.0.1", gc_data_port=port, gc_return_port=0,
                              mirror_port=0),
    )
    ref = Referee(config=config, clock=SystemClock(), log_dir=tmp_path)
    ref.start_network()
    try:
        assert ref.network is not None and ref.mirror is not None
        red1 = robots["127.0.0.2"]
        for _ in range(20):
            red1.sendto(encode_return(ReturnData(25, 1, ReturnMessage.GOALKEEPER)),
                        ref.network.return_address)
        red1.sendto(encode_return(ReturnData(8, 2, ReturnMessage.MAN_PENALISE)),
                    ref.network.return_address)
        red1.sendto(encode_return(ReturnData(8, 1, ReturnMessage.ALIVE)),
                    ref.network.return_address)
        with udp("127.0.0.9", 0) as stranger:
            stranger.sendto(b"let me in", ref.mirror.address)
        assert wait_for(lambda: ref.spoofing.total == 22)
        assert wait_for(lambda: RobotId(RED, 1) in ref.network.links())  # type: ignore[union-attr]
        links = ref.network.links()
        assert RobotId(BLUE, 1) not in links and RobotId(RED, 2) not in links
        assert ref.network.stats().spoofed == 21
        assert ref.network.take_goalkeeper_claims() == []
        ref.step(snapshot(0, (robot(RED, 1, -1, 0),)))
        result = ref.result()
    finally:
        ref.close()
    spoofing = result["spoofing"]
    assert isinstance(spoofing, dict) and spoofing["total"] == 22
    attempts = {(a["channel"], a["claimed"], a["message"]): a for a in spoofing["attempts"]}
    keeper = attempts[("gamecontroller", "blue-1", "GOALKEEPER")]
    assert keeper["sender"] == "127.0.0.2" and keeper["sender_robot"] == "red-1"
    assert keeper["count"] == 20
    assert attempts[("gamecontroller", "red-2", "MAN_PENALISE")]["count"] == 1
    assert attempts[("mirror", None, "team message")]["sender"] == "127.0.0.9"
    log = (tmp_path / "referee.log").read_text()
    assert "GOALKEEPER from 127.0.0.2 (red-1) claiming to be blue-1 ignored" in log
    assert "declared itself goalkeeper" not in log
    events = (tmp_path / "referee_events.jsonl").read_text().splitlines()
    assert sum('"type": "spoofing"' in line for line in events) == 3
    assert "spoofed: 21" in (tmp_path / "gamecontroller.log").read_text()


def test_a_game_state_not_sent_yet_goes_out_when_the_network_closes(
    robots: dict[str, socket.socket],
) -> None:
    """League referee (``referee.py``): after FINISHED the game runs on (``END_OF_GAME_TIMEOUT``)
    while the GameController keeps broadcasting, so robots see FINISHED; a FINISHED entered
    just before the network closes is sent as it closes."""
    port = robots["127.0.0.2"].getsockname()[1]
    net = GameControllerNetwork(
        bind_host="127.0.0.1", data_port=port, return_port=0, targets=["127.0.0.2"],
        team_numbers={8: RED, 25: BLUE}, send_rate_hz=2.0, clock=SystemClock(),
    )
    ref = Referee(config=make_config(), clock=FakeClock())
    playing, finished = bytearray(ref.packet()), bytearray(ref.packet())
    playing[9], finished[9] = 3, 4
    with net:
        net.publish(bytes(playing), state_changed=True)
        assert wait_for(lambda: net.stats().packets_sent >= 1)
        net.publish(bytes(finished), state_changed=True)
    got = receive_all(robots["127.0.0.2"], 0.3)
    states = [decode_game_state(raw).state for raw, _ in got]
    assert states[-1] == 4, states
    numbers = [decode_game_state(raw).packet_number for raw, _ in got]
    assert numbers == list(range(numbers[0], numbers[0] + len(numbers)))
