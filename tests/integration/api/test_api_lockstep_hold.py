"""A plain lockstep match holding for a wall-clock wait (before the first READY): what a
connected client gets, over real sockets on 127.0.0.1 (fake world, real server)."""

from __future__ import annotations

import threading

from contracts.match_spec import NetworkSpec
from robot.client import RobotClient
from simulator.api import ApiServer, FakeDeviceWorld, LockstepSettings, PlayerEndpoint
from simulator.api.endpoints import free_ports
from simulator.api.stepping import hold_text
from tests.integration.api.harness import RED1, wait_until


def test_a_client_connected_during_the_hold_gets_one_measurement_saying_why() -> None:
    """League referee (``referee.py``): it keeps stepping during the 120 s wall-clock wait
    before the first READY, so clients get measurements; a lockstep match holds instead (its
    steps would depend on wall-clock timing) and tells each client so, once, in a measurement
    of the held time; nothing simulated changes."""
    world = FakeDeviceWorld((RED1,))
    [port] = free_ports(1)
    server = ApiServer(
        world=world,
        endpoints=[PlayerEndpoint(robot=RED1, port=port, hosts=("127.0.0.1",), team_size=1)],
        network=NetworkSpec(api_bind_host="127.0.0.1"),
        lockstep=LockstepSettings(deadline_s=0.05, time_bank_s=1.0),
    )
    server.start()
    clients: list[RobotClient] = []
    connecting = threading.Thread(
        target=lambda: clients.append(
            RobotClient("127.0.0.1", port, retries=20, retry_interval_s=0.05).connect()
        )
    )
    connecting.start()
    try:
        def connected() -> bool:
            server.poll(0.01)
            return bool(server.connected())

        wait_until(connected)
        connecting.join(timeout=10)
        [client] = clients
        assert server.hold_notice(0, hold_text(0)) == 1
        assert server.hold_notice(0, hold_text(0)) == 0  # once per client and hold
        notice = client.receive(timeout=5)
        assert notice.time == 0 and not notice.position_sensors
        [message] = notice.messages
        assert "simulated time holds at 0 ms" in message.text
        assert "wall-clock" in message.text
        assert world.sim_time_ms == 0 and world.calls == []  # nothing simulated was touched
        client.close()
    finally:
        server.close()
