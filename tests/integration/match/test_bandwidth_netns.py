"""Traffic control in a real network namespace: the limits land on the namespace's ``eth0`` and
on its host-side peer, the counters read, the shaping comes off, and the thread that asked is
left in its own namespace (the netlink socket is made by a thread that enters the namespace)."""

from __future__ import annotations

import os
import random
import subprocess
import sys
import uuid
from collections.abc import Iterator

import pytest

from orchestrator import bandwidth
from orchestrator.bandwidth import BandwidthError, RobotShaping

pytestmark = [pytest.mark.root]


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True)


def _qdiscs(device: str, netns: str | None = None) -> str:
    inside = ["nsenter", f"--net={netns}"] if netns else []
    return subprocess.run([*inside, "tc", "qdisc", "show", "dev", device], check=True,
                          capture_output=True, text=True).stdout  # fmt: skip


@pytest.fixture
def robot_netns() -> Iterator[tuple[str, str, str]]:
    """A namespace with ``eth0``, the peer of ``hlvsbw<id>`` on the host (as a holder's), and
    the peer's address (a /30 of the benchmarking range)."""
    tag = uuid.uuid4().hex[:6]
    name, peer = f"hlvs-bw-{tag}", f"hlvsbw{tag}"
    net = f"198.18.{random.randrange(256)}.{4 * random.randrange(64)}"
    base = net.rsplit(".", 1)
    host_ip, robot_ip = f"{base[0]}.{int(base[1]) + 1}", f"{base[0]}.{int(base[1]) + 2}"
    _ip("netns", "add", name)
    try:
        _ip("link", "add", peer, "type", "veth", "peer", "name", "eth0", "netns", name)
        _ip("addr", "add", f"{host_ip}/30", "dev", peer)
        _ip("link", "set", peer, "up")
        _ip("-n", name, "addr", "add", f"{robot_ip}/30", "dev", "eth0")
        _ip("-n", name, "link", "set", "eth0", "up")
        yield f"/run/netns/{name}", peer, host_ip
    finally:
        subprocess.run(["ip", "link", "del", peer], capture_output=True)
        subprocess.run(["ip", "netns", "del", name], capture_output=True)


def _own_netns() -> tuple[int, int]:
    st = os.stat("/proc/thread-self/ns/net")
    return st.st_dev, st.st_ino


def test_limits_land_in_the_namespace_and_on_its_host_peer(
    robot_netns: tuple[str, str, str],
) -> None:
    netns, peer, host_ip = robot_netns
    before = _own_netns()
    shaping = RobotShaping(api_rate_bit=40_000_000, comm_rate_bit=8_000_000,
                           simulator_ip="172.30.0.2", teammate_ips=("172.30.0.11",),
                           mirror_port=3737)  # fmt: skip
    applied = bandwidth.apply_netns(netns, shaping)
    assert _own_netns() == before  # this thread never left its namespace
    assert applied.netns == netns and applied.device == "eth0"
    assert "htb" in _qdiscs("eth0", netns), _qdiscs("eth0", netns)
    assert "htb" in _qdiscs(peer), _qdiscs(peer)
    before_send = bandwidth.read_counters(applied)
    # five 1000-byte datagrams from the namespace to the host: the default class (api)
    send = ("import socket; s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM); "
            f"[s.sendto(b'x' * 1000, ('{host_ip}', 9)) for _ in range(5)]")  # fmt: skip
    subprocess.run(["nsenter", f"--net={netns}", sys.executable, "-c", send], check=True)
    after_send = bandwidth.read_counters(applied)
    assert after_send.sent_api_bytes - before_send.sent_api_bytes >= 5 * 1028, after_send
    assert after_send.sent_comm_bytes == before_send.sent_comm_bytes
    bandwidth.remove(applied)
    assert "htb" not in _qdiscs("eth0", netns)
    assert "htb" not in _qdiscs(peer)
    assert _own_netns() == before


def test_a_namespace_that_is_gone_is_named_in_the_error() -> None:
    shaping = RobotShaping(
        api_rate_bit=1_000_000, comm_rate_bit=1_000_000, simulator_ip="172.30.0.2", teammate_ips=()
    )
    missing = f"/run/netns/hlvs-bw-missing-{uuid.uuid4().hex[:6]}"
    with pytest.raises(BandwidthError) as caught:
        bandwidth.apply_netns(missing, shaping)
    assert missing in str(caught.value)
    assert "No such file" in str(caught.value)
