"""Red robots reach their simulator and teammates, and nothing else: not blue, not the control
network, not a service the host binds on 0.0.0.0."""

from __future__ import annotations

import ipaddress
import json
import socket

import pytest

from orchestrator.match.layout import Subnet
from orchestrator.runtime.port import ContainerRequest, NetworkRequest
from tests.integration.match.conftest import MatchFactory

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_red_reaches_only_its_simulator_and_teammates(play: MatchFactory) -> None:
    host_server = socket.socket()
    host_server.bind(("0.0.0.0", 0))
    host_server.listen(8)
    host_port = host_server.getsockname()[1]
    subnets: dict[str, Subnet] = {}  # role -> subnet, as the match creates its networks

    def write_targets(request: ContainerRequest | NetworkRequest) -> None:
        """Once red 1's container is made (every network is by then), before it runs: where
        its probe is to try to connect, in its /robocup-logs."""
        if isinstance(request, NetworkRequest):
            subnets[request.name.rsplit("-", 1)[1]] = Subnet(
                network=ipaddress.IPv4Network(request.subnet))
            return
        if not request.name.endswith("-red-1"):
            return
        folder = next(m.source for m in request.mounts if m.target == "/robocup-logs")
        targets = {
            "simulator": [subnets["red"].simulator, 10001],
            "teammate": [subnets["red"].robot(2), 5000],
            "blue robot": [subnets["blue"].robot(1), 5000],
            "blue simulator address": [subnets["blue"].simulator, 10021],
            "control network": [subnets["control"].simulator, 10001],
            "host via gateway": [subnets["red"].gateway, host_port],
            "host via control gateway": [subnets["control"].gateway, host_port],
        }
        (folder / "targets.json").write_text(json.dumps(targets))

    try:
        outcome = play(red=[["probe"], ["listen"]], blue=[["listen"]], sim=("10",),
                       on_created=write_targets)
    finally:
        host_server.close()
    reach = json.loads((outcome.out_dir / "teams/red/1/robocup-logs/reach.json").read_text())
    assert reach["simulator"] == "connected"
    assert reach["teammate"] == "connected"
    for name in ("blue robot", "blue simulator address", "control network", "host via gateway",
                 "host via control gateway"):
        assert reach[name].startswith("failed"), (name, reach[name])
