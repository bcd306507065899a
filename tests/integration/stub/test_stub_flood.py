"""``flood``: the stub pushes as much as it can to the robot API server and to the team mirror."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

from tests.integration.api.harness import RED1, free_ports, running_server


def test_flood_saturates_the_api_connection_and_the_mirror(tmp_path: Path) -> None:
    mirror = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    mirror.bind(("127.0.0.1", 0))
    mirror.settimeout(0.1)
    gc_data, gc_return = free_ports(2)
    with running_server(robots=[RED1]) as (driver, ports):
        env = {
            **os.environ,
            "ROBOCUP_ROBOT_ID": "1",
            "ROBOCUP_TEAM_COLOR": "red",
            "ROBOCUP_SIMULATOR_ADDR": f"127.0.0.1:{ports[RED1]}",
            "ROBOCUP_MIRROR_SERVER_IP": "127.0.0.1",
            "ROBOCUP_LOG_DIR": str(tmp_path),
        }
        argv = ["flood", "--mirror-port", str(mirror.getsockname()[1])]
        argv += ["--gc-data-port", str(gc_data), "--gc-return-port", str(gc_return)]
        stub_log = tmp_path / "stub.err"
        with stub_log.open("w") as err:
            proc = subprocess.Popen(
                [sys.executable, "-m", "robot.stub", *argv], env=env, stderr=err
            )
        received = 0
        try:
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                try:
                    received += len(mirror.recv(2048))
                except TimeoutError:
                    pass
                stats = driver.server.statistics().get("red-1", {})
                if received > 1_000_000 and stats.get("bytes_in", 0) > 20_000_000:
                    break
            stats = driver.server.statistics()["red-1"]
            assert received > 1_000_000, f"mirror got {received} bytes"
            # the stub keeps one connection and floods it (two threads sending on one client:
            # each frame whole), so the server reads far more than it could in 30 s otherwise
            assert stats["bytes_in"] > 20_000_000, (
                f"{stats['bytes_in']} bytes in, {len(stats['connects'])} connections, first"
                f" drops {stats['disconnect_reasons'][:3]}; stub: {stub_log.read_text()[-2000:]}"
            )
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=20) == 0
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
            mirror.close()
