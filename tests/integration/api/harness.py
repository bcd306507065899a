"""A robot API server on 127.0.0.1 driven by a background step loop.

The world is the real MuJoCo world unless a test passes ``world=`` (the fake device world is for
tests that inspect the calls the server makes or flip limp / removed flags from the test thread).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any

from contracts.ids import RobotId, TeamColor
from contracts.match_spec import NetworkSpec
from simulator.api import (
    ApiServer,
    FakeCameraRenderer,
    LockstepSettings,
    PlayerEndpoint,
    RenderWorker,
    wait_lockstep,
)
from simulator.api.endpoints import free_ports

RED1 = RobotId(TeamColor.RED, 1)
RED2 = RobotId(TeamColor.RED, 2)
BLUE1 = RobotId(TeamColor.BLUE, 1)


def real_world(robots: Sequence[RobotId]) -> Any:
    from simulator.world import RobotPlacement, World

    placements = [
        RobotPlacement(
            id=r,
            model="kid-default",
            x_m=(-1.0 if r.team is TeamColor.RED else 1.0) * r.number,
            y_m=0.0,
            yaw_rad=0.0 if r.team is TeamColor.RED else math.pi,
        )
        for r in robots
    ]
    return World.create(field_class="kid", robots=placements, seed=11)


def local_server(
    world: Any, robots: Sequence[RobotId], **options: Any
) -> tuple[ApiServer, list[int]]:
    """A server (not started) of ``robots`` in ``world`` on free ports of 127.0.0.1, in async
    stepping unless ``options`` say otherwise; and its ports, in the order of ``robots``."""
    ports = free_ports(len(robots))
    server = ApiServer(
        world=world,
        endpoints=[PlayerEndpoint(robot=r, port=p, hosts=("127.0.0.1",), team_size=4)
                   for r, p in zip(robots, ports, strict=True)],  # fmt: skip
        network=NetworkSpec(api_bind_host="127.0.0.1"),
        **options,
    )
    return server, ports


def wait_until(predicate: Callable[[], Any], timeout_s: float = 10.0) -> Any:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.005)
    raise AssertionError("condition not reached in time")


class Driver:
    """Runs steps in a thread: [lockstep wait] -> apply requests -> world.step -> publish."""

    def __init__(
        self, server: ApiServer, world: Any, lockstep: LockstepSettings | None, pause_s: float
    ) -> None:
        self.server = server
        self.world = world
        self.lockstep = lockstep
        self.pause_s = pause_s
        self.stop = threading.Event()
        self.error: BaseException | None = None
        self.steps = 0
        self.max_steps: int | None = None
        self.thread = threading.Thread(target=self._run, daemon=True)

    def _run(self) -> None:
        try:
            while not self.stop.is_set():
                if self.max_steps is not None and self.steps >= self.max_steps:
                    self.server.poll(0.01)
                    continue
                if self.lockstep is not None:
                    wait_lockstep(self.server, self.lockstep)
                self.server.apply_requests(self.world.sim_time_ms + 8)
                self.world.step()
                self.server.publish(self.world.sim_time_ms)
                self.steps += 1
                self.server.poll(self.pause_s)
        except BaseException as exc:  # reported to the test
            self.error = exc
            raise


@contextmanager
def running_server(
    *,
    robots: Sequence[RobotId] = (RED1, RED2, BLUE1),
    hosts: tuple[str, ...] = ("127.0.0.1",),
    network: NetworkSpec | None = None,
    lockstep: LockstepSettings | None = None,
    world: Any = None,
    cameras: bool = False,
    worker: RenderWorker | None = None,
    pause_s: float = 0.002,
    team_size: int = 4,
    hold: bool = False,
    send_thread: bool | None = None,
) -> Iterator[tuple[Driver, dict[RobotId, int]]]:
    world = world if world is not None else real_world(robots)
    ports = dict(zip(robots, free_ports(len(robots)), strict=True))
    endpoints = [
        PlayerEndpoint(robot=r, port=p, hosts=hosts, team_size=team_size) for r, p in ports.items()
    ]
    network = network or NetworkSpec(api_bind_host="127.0.0.1")
    if cameras:
        worker = RenderWorker(
            capture=lambda: None,
            make_render=lambda: lambda _s, r, w, h: FakeCameraRenderer(None, w, h).render(r),
        )
    server = ApiServer(
        world=world, endpoints=endpoints, network=network, lockstep=lockstep, cameras=worker,
        send_thread=send_thread,
    )
    server.start()
    driver = Driver(server, world, lockstep, pause_s)
    if hold:
        driver.max_steps = 0
    driver.thread.start()
    try:
        yield driver, ports
    finally:
        driver.stop.set()
        driver.thread.join(timeout=10)
        server.close()
        if worker is not None:
            worker.close()
    if driver.error is not None:
        raise driver.error
