"""A team robot model (the Wolfgang package) served over the robot API exactly as the built-in:
its own device names, the HLVS warnings for names it does not have, the same measurements."""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest

from contracts.ids import RobotId, TeamColor
from robot.client import RobotClient
from simulator.api.world_cameras import world_render_worker
from simulator.world import RobotPlacement, World
from tests.integration.api.harness import RED1, running_server

WOLFGANG = Path(__file__).resolve().parents[3] / "configs" / "examples" / "robots" / "wolfgang"
BLUE1 = RobotId(TeamColor.BLUE, 1)


def test_client_enables_sensors_and_moves_the_head_by_hlvs_names() -> None:
    world = World.create(
        field_class="kid",
        robots=[
            RobotPlacement(id=RED1, model=str(WOLFGANG), x_m=-1.0, y_m=0.0, yaw_rad=0.0),
            RobotPlacement(id=BLUE1, model="kid-default", x_m=1.0, y_m=0.0, yaw_rad=math.pi),
        ],
        seed=3,
    )
    worker = world_render_worker(world)
    with running_server(robots=(RED1, BLUE1), world=world, worker=worker) as (_d, ports):
        client = RobotClient("127.0.0.1", ports[RED1], retries=3, retry_interval_s=0.1)
        with client.connect() as robot:
            robot.enable_many(
                {"HeadPanS": 8, "HeadTiltS": 8, "Accelerometer": 8, "Gyro": 8, "llb": 8,
                 "Camera": 32, "NeckS": 8}
            )
            warnings: list[str] = []
            for _ in range(80):
                msg = robot.receive(timeout=10)
                warnings += [m.text for m in msg.messages]
                robot.set_positions({"HeadPan": 0.5, "HeadTilt": -0.3, "Neck": 1.0})
            # the catalogue's servo takes a fraction of a second to settle; the free-running
            # world may be ahead of the client's reading by the messages in flight
            deadline = time.monotonic() + 10.0
            while True:
                last = robot.receive(timeout=10)
                sensors = {s.name: s.value for s in last.position_sensors}
                settled = abs(sensors.get("HeadPanS", 0.0) - 0.5) < 0.05
                if (last.cameras and settled) or time.monotonic() > deadline:
                    break
    assert set(sensors) == {"HeadPanS", "HeadTiltS"}
    assert sensors["HeadPanS"] == pytest.approx(0.5, abs=0.05)
    assert sensors["HeadTiltS"] == pytest.approx(-0.3, abs=0.05)
    assert 8.0 < last.accelerometers[0].value.Z < 11.5  # standing, gravity along the IMU's z
    assert last.gyros and [f.name for f in last.forces] == ["llb"]
    image = last.cameras[0]
    assert (image.name, image.width, image.height) == ("Camera", 320, 240)
    assert len(image.image) == 320 * 240 * 3 and len(set(image.image[::997])) > 3
    # names a Wolfgang does not have get the HLVS warnings, once each
    assert sum("NeckS" in w for w in warnings) == 1
    assert sum('"Neck"' in w for w in warnings) == 1
