"""Red robots reach their simulator and teammates, and nothing else: not blue, not the control
network, not a service the host binds on 0.0.0.0."""

from __future__ import annotations

import json
import socket
import threading
import time
from pathlib import Path

import pytest

from orchestrator.match import MatchRunner
from tests.integration.match.conftest import MatchFactory

pytestmark = [pytest.mark.docker, pytest.mark.root]


def test_red_reaches_only_its_simulator_and_teammates(play: MatchFactory) -> None:
    host_server = socket.socket()
    host_server.bind(("0.0.0.0", 0))
    host_server.listen(8)
    host_port = host_server.getsockname()[1]
    holder: list[MatchRunner] = []

    def write_targets() -> None:
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline:
            runner = holder[0] if holder else None
            folders = runner.started.log_folders if runner else {}
            if runner is not None and len(runner.started.robot_ids) == 3 and "red-1" in folders:
                subnets = runner.started.subnets
                targets = {
                    "simulator": [subnets["red"].simulator, 10001],
                    "teammate": [subnets["red"].robot(2), 5000],
                    "blue robot": [subnets["blue"].robot(1), 5000],
                    "blue simulator address": [subnets["blue"].simulator, 10021],
                    "control network": [subnets["control"].simulator, 10001],
                    "host via gateway": [subnets["red"].gateway, host_port],
                    "host via control gateway": [subnets["control"].gateway, host_port],
                }
                path = Path(folders["red-1"].path) / "targets.json"
                path.write_text(json.dumps(targets))
                return
            time.sleep(0.05)

    writer = threading.Thread(target=write_targets, daemon=True)
    writer.start()
    try:
        outcome = play(red=[["probe"], ["listen"]], blue=[["listen"]], sim=("10",),
                       runner_hook=holder.append)
    finally:
        host_server.close()
    writer.join(timeout=5)
    reach = json.loads((outcome.out_dir / "teams/red/1/robocup-logs/reach.json").read_text())
    assert reach["simulator"] == "connected"
    assert reach["teammate"] == "connected"
    for name in ("blue robot", "blue simulator address", "control network", "host via gateway",
                 "host via control gateway"):
        assert reach[name].startswith("failed"), (name, reach[name])
