"""Session and quota rules without sockets (fake device world)."""

from __future__ import annotations

import pytest

from contracts.ids import RobotId, TeamColor
from contracts.robot_api import messages_pb2 as pb
from simulator.api import FakeDeviceWorld, NetworkQuota, RobotSession, rendering_bandwidth_mb_s

RED1 = RobotId(TeamColor.RED, 1)


def _session(world: FakeDeviceWorld, quota: float = 87.5) -> RobotSession:
    return RobotSession(robot=RED1, world=world, rendering_quota_mb_s=quota, clock_ms=lambda: 42)


def _enable(session: RobotSession, t_ms: int, **periods: int) -> None:
    request = pb.ActuatorRequests()
    for name, period in periods.items():
        request.sensor_time_steps.add(name=name, timeStep=period)
    session.apply(request, step_time_ms=t_ms)


def test_sensor_reported_one_period_after_enabling_then_every_period() -> None:
    world = FakeDeviceWorld([RED1])
    session = _session(world)
    _enable(session, 16, NeckS=8, Gyro=24)
    times = {}
    for t in range(16, 120, 8):
        measurement = session.measure(t)
        msg, jobs = measurement.parsed(), measurement.jobs
        assert not jobs and msg.real_time == 42 and msg.time == t
        times[t] = (bool(msg.position_sensors), bool(msg.gyros))
    assert times[16] == (False, False)  # not in the step it was enabled
    assert [t for t, (neck, _) in times.items() if neck] == list(range(24, 120, 8))
    assert [t for t, (_, gyro) in times.items() if gyro] == [40, 64, 88, 112]
    _enable(session, 120, NeckS=8)  # same period again: no re-synchronisation
    assert session.measure(120).parsed().position_sensors


def test_camera_jobs_and_rendering_quota() -> None:
    world = FakeDeviceWorld([RED1])
    assert rendering_bandwidth_mb_s(1920, 1080, 16) == pytest.approx(370.8, abs=0.1)
    session = _session(world, quota=7.0)
    _enable(session, 8, Camera=16)  # 13.7 MB/s > 7 MB/s
    msg = session.measure(8).parsed()
    assert [m.text for m in msg.messages] == [
        "requested rendering bandwidth is above the limit (14MB/s > 7MB/s)"
    ]
    _enable(session, 16, Camera=32)  # 6.9 MB/s fits
    assert not session.measure(16).header.messages
    _enable(session, 24, Camera=64)
    session.measure(24)
    jobs = [job for t in range(32, 160, 8) for job in session.measure(t).jobs]
    assert [job.time_ms for job in jobs] == [88, 152]
    assert (jobs[0].width, jobs[0].height) == (320, 240)


def test_limp_caches_and_reapplies_every_command_kind() -> None:
    world = FakeDeviceWorld([RED1])
    session = _session(world)
    world.limp.add(RED1)
    session.update_limp()
    request = pb.ActuatorRequests()
    request.motor_positions.add(name="Neck", position=0.4)
    request.motor_velocities.add(name="Neck", velocity=2.0)
    request.motor_torques.add(name="Head", torque=0.5)
    session.apply(request, step_time_ms=8)
    assert world.calls == []
    world.limp.discard(RED1)
    session.update_limp()
    assert sorted(call[0] for call in world.calls) == ["position", "torque", "velocity"]


def test_quota_window_slides() -> None:
    quota = NetworkQuota(quota_mb_s=1.0 / 1024)  # 1024 bytes per second
    assert quota.error_text == "0.000977 MB/s quota exceeded."
    assert quota.allows(1000, 0)
    quota.record(1000, 0)
    assert not quota.allows(100, 500)
    assert quota.allows(100, 1000)  # the first message left the 1 s window


def test_render_worker_threads_complete_every_job() -> None:
    import select

    from simulator.api import FakeCameraRenderer, RenderWorker
    from simulator.api.measurement import CameraJob

    worker = RenderWorker(
        capture=lambda: None,
        make_render=lambda: lambda _s, r, w, h: FakeCameraRenderer(None, w, h).render(r),
        threads=2,
    )
    robots = [RobotId(TeamColor.BLUE, n) for n in (1, 2, 3)]
    for t in (8, 16):
        worker.submit([CameraJob(r, "Camera", 4, 2, t, pb.CameraMeasurement()) for r in robots])
    done = []
    while len(done) < 6:
        assert select.select([worker.wake_fd], [], [], 5.0)[0], "no render completed in time"
        done += worker.completed()
    worker.close()
    assert worker.in_flight == 0 and worker.frames == 6
    assert sorted((job.time_ms, image[0]) for job, image in done) == [
        (t, n) for t in (8, 16) for n in (1, 2, 3)
    ]
    assert all(len(image) == 4 * 2 * 3 for _, image in done)


def test_motor_forces_drive_a_rotational_motor_as_its_torque() -> None:
    """The league's player calls ``setForce`` for ``motor_forces`` and ``setTorque`` for
    ``motor_torques`` (hlvs_webots ``controllers/player/player.cpp:478-496``). In Webots'
    controller library ``wb_motor_set_torque`` is ``wb_motor_set_force`` (``motor.c``, the
    aliases), and both switch the motor from its PID to that torque: on a rotational motor
    (every joint of a humanoid) a force request is the same torque request. Held while limp
    and applied again, as a torque is."""
    world = FakeDeviceWorld([RED1])
    session = _session(world)
    forces = pb.ActuatorRequests()
    forces.motor_forces.add(name="Head", force=0.7)
    session.apply(forces, step_time_ms=8)
    torques = pb.ActuatorRequests()
    torques.motor_torques.add(name="Head", torque=0.7)
    session.apply(torques, step_time_ms=16)
    assert world.calls[0] == world.calls[1]
    assert world.calls[0] == ("torque", RED1, "Head", (0.7,))
    world.calls.clear()
    world.limp.add(RED1)
    session.update_limp()
    session.apply(forces, step_time_ms=24)
    assert world.calls == []
    world.limp.discard(RED1)
    session.update_limp()
    assert [call[0] for call in world.calls] == ["torque"]
