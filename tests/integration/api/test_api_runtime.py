"""The simulator process: contract files, lockstep determinism, SIGTERM, telemetry."""

from __future__ import annotations

import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import pytest

from contracts.match_spec import MatchSpec
from robot.client import ConnectionClosed, RobotClient
from simulator.runtime import run_match
from tests.integration.api.harness import free_ports, wait_until
from tests.integration.api.match_specs import short_spec

CONTRACT_FILES = (
    "sim_result.json", "replay.hlvsrec", "referee.log", "referee_events.jsonl",
    "gamecontroller.log",
)  # fmt: skip


def _robot_loop(port: int, trace: list[tuple[int, float]]) -> None:
    """A deterministic controller: joint targets from time and sensor feedback. It tries to
    connect for 30 s: on a loaded machine the server listens only after more than 4 s."""
    client = RobotClient("127.0.0.1", port, retries=1500, retry_interval_s=0.02).connect()
    try:
        client.enable_many({"NeckS": 8, "LegUpperLS": 8, "Accelerometer": 8})
        for msg in client:
            neck = msg.position_sensors[0].value if msg.position_sensors else 0.0
            acc = msg.accelerometers[0].value.Z if msg.accelerometers else 0.0
            trace.append((msg.time, round(neck, 12)))
            client.set_positions(
                {"Neck": 0.5 * math.sin(msg.time / 300.0) + 0.1 * neck, "LegUpperL": 0.01 * acc}
            )
    except ConnectionClosed:
        pass
    finally:
        client.close()


def _play(spec: MatchSpec, out: Path) -> tuple[int, list[tuple[int, float]]]:
    trace: list[tuple[int, float]] = []
    robots = [p.port for p in spec.red.players + spec.blue.players]
    threads = [threading.Thread(target=_robot_loop, args=(port, trace if i == 0 else []))
               for i, port in enumerate(robots)]  # fmt: skip
    for thread in threads:
        thread.start()
    code = run_match(spec, out, gc_network=False)
    for thread in threads:
        thread.join(timeout=10)
    return code, trace


def _play_twice(spec: MatchSpec, tmp_path: Path) -> tuple[list[tuple[int, float]], dict[str, Any]]:
    """Play ``spec`` twice with the same clients: the same joint trace and the same recording
    byte for byte; the first run's trace and sim_result."""
    code_a, trace_a = _play(spec, tmp_path / "a")
    code_b, trace_b = _play(spec, tmp_path / "b")
    assert code_a == code_b == 0
    assert len(trace_a) > 100 and trace_a == trace_b
    replay_a = (tmp_path / "a" / "replay.hlvsrec").read_bytes()
    assert replay_a == (tmp_path / "b" / "replay.hlvsrec").read_bytes()
    result: dict[str, Any] = json.loads((tmp_path / "a" / "sim_result.json").read_text())
    assert result["robots"]["red-1"]["messages_in"] > 100
    assert result["robots"]["red-1"]["slow_periods"] == 0
    return trace_a, result


def test_lockstep_match_replays_identically(tmp_path: Path) -> None:
    spec = short_spec(stepping="lockstep", timing=replace(
        short_spec().timing, wait_before_first_ready_real_s=1.0))  # fmt: skip
    _, result = _play_twice(spec, tmp_path)
    assert result["state"] == "FINISHED" and result["winner"] == "draw"


def test_pipelined_match_replays_identically_and_differs_from_lockstep(tmp_path: Path) -> None:
    timing = replace(short_spec().timing, wait_before_first_ready_real_s=1.0)
    spec = short_spec(stepping="pipelined", timing=timing)
    trace_a, result = _play_twice(spec, tmp_path)
    assert result["stepping"] == "pipelined" and result["state"] == "FINISHED"
    # the same clients in lockstep: the actions apply one step earlier, so the joints differ
    code_l, trace_l = _play(replace(spec, stepping="lockstep"), tmp_path / "l")
    assert code_l == 0 and len(trace_l) > 100
    assert trace_l != trace_a


def _spawn(spec: MatchSpec, out: Path) -> subprocess.Popen[str]:
    spec_path = out.parent / f"{out.name}_spec.json"
    spec_path.write_text(spec.to_json())
    return subprocess.Popen(
        [sys.executable, "-m", "simulator", "run", "--spec", str(spec_path), "--out", str(out)],
        stderr=subprocess.PIPE, text=True,
    )  # fmt: skip


def test_async_process_writes_the_contract_files(tmp_path: Path) -> None:
    spec = short_spec(stepping="async")
    proc = _spawn(spec, tmp_path / "out")
    trace: list[tuple[int, float]] = []
    _robot_loop(spec.red.players[0].port, trace)
    _, stderr = proc.communicate(timeout=120)
    assert proc.returncode == 0, stderr[-2000:]
    for name in CONTRACT_FILES:
        assert (tmp_path / "out" / name).exists(), name
    result = json.loads((tmp_path / "out" / "sim_result.json").read_text())
    for key in ("match_id", "seed", "score", "winner", "sim_time_ms", "real_time_s",
                "real_time_factor", "events_summary", "robots", "versions"):  # fmt: skip
        assert key in result, key
    assert result["robots"]["red-1"]["connects"] and result["robots"]["red-1"]["messages_out"]
    assert "red-1: client 127.0.0.1" in stderr and "connected on port" in stderr
    assert [t for t, _ in trace] == list(range(trace[0][0], trace[-1][0] + 8, 8))


def test_sigterm_stops_cleanly_with_results(tmp_path: Path) -> None:
    spec = short_spec(stepping="async", maximum_real_time_factor=1.0)
    spec = replace(spec, timing=replace(spec.timing, half_duration_s=600.0))
    proc = _spawn(spec, tmp_path / "out")
    with RobotClient(
        "127.0.0.1", spec.red.players[0].port, retries=600, retry_interval_s=0.05
    ) as c:
        c.receive(timeout=30)
        proc.send_signal(signal.SIGTERM)
        with pytest.raises(ConnectionClosed):
            for _ in range(10_000):
                c.receive(timeout=30)
    _, stderr = proc.communicate(timeout=60)
    assert proc.returncode == 130, stderr[-2000:]
    result = json.loads((tmp_path / "out" / "sim_result.json").read_text())
    assert result["stop_reason"] == "SIGTERM" and result["winner"] is None
    assert 0 < result["real_time_factor"] <= 1.1  # paced by maximum_real_time_factor 1.0
    assert (tmp_path / "out" / "replay.hlvsrec").stat().st_size > 0


def test_telemetry_state_and_events_over_zenoh(tmp_path: Path) -> None:
    import zenoh

    from simulator.telemetry import zenoh_config

    port = free_ports(1)[0]
    spec = short_spec(stepping="async", maximum_real_time_factor=2.0)
    spec = replace(spec, network=replace(spec.network, telemetry_listen=f"tcp/127.0.0.1:{port}"))
    proc = _spawn(spec, tmp_path / "out")
    states: list[dict[str, object]] = []
    events: list[dict[str, object]] = []
    session = None
    try:

        def connect() -> object:
            try:
                return zenoh.open(zenoh_config(connect=f"tcp/127.0.0.1:{port}", mode="client"))
            except zenoh.ZError:
                time.sleep(0.1)
                return None

        session = wait_until(connect, 30)
        session.declare_subscriber(  # type: ignore[attr-defined]
            "hlvs/test-match/state", lambda s: states.append(json.loads(s.payload.to_bytes()))
        )
        session.declare_subscriber(  # type: ignore[attr-defined]
            "hlvs/test-match/events", lambda s: events.append(json.loads(s.payload.to_bytes()))
        )
        wait_until(lambda: any(s["state"] == "PLAYING" for s in states), 60)
        wait_until(lambda: events, 30)
    finally:
        proc.wait(timeout=120)
        if session is not None:
            session.close()  # type: ignore[attr-defined]
    sample = states[-1]
    assert set(sample) >= {
        "sim_time_ms",
        "real_time_factor",
        "state",
        "secondary_state",
        "half",
        "secs_remaining",
        "score",
        "connected",
        "stepping",
    }
    assert sample["stepping"] == "async"
    assert {"type", "sim_time_ms"} <= set(events[0])


def test_invalid_spec_exits_2_naming_file_and_field(tmp_path: Path) -> None:
    data = json.loads(short_spec().to_json())
    data["stepping"] = "fast"
    spec_path = tmp_path / "bad_spec.json"
    spec_path.write_text(json.dumps(data))
    proc = subprocess.run(
        [sys.executable, "-m", "simulator", "run", "--spec", str(spec_path), "--out",
         str(tmp_path / "out")],
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert proc.returncode == 2
    assert str(spec_path) in proc.stderr and "/stepping" in proc.stderr
    assert "Traceback" not in proc.stderr


def _camera_loop(port: int, images: list[bytes]) -> None:
    """A client that enables the head camera and keeps every image."""
    client = RobotClient("127.0.0.1", port, retries=1500, retry_interval_s=0.02).connect()
    try:
        client.enable_many({"NeckS": 8, "Camera": 32})
        for msg in client:
            images.extend(bytes(camera.image) for camera in msg.cameras)
            client.set_positions({"Neck": 0.0})
    except ConnectionClosed:
        pass
    finally:
        client.close()


def test_a_match_renders_cameras_in_worker_processes_on_the_cpu(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """On the CPU renderer with two CPUs or more a match renders the robot cameras in worker
    processes (one per CPU, at most four): the robot gets its images and ``sim_result.json``
    says how they were rendered."""
    monkeypatch.setenv("MUJOCO_GL", "osmesa")
    cpus = len(os.sched_getaffinity(0))
    spec = short_spec(stepping="lockstep")
    images: list[bytes] = []
    ports = [p.port for p in spec.red.players + spec.blue.players]
    threads = [threading.Thread(target=_camera_loop, args=(ports[0], images)),
               threading.Thread(target=_robot_loop, args=(ports[1], []))]  # fmt: skip
    for thread in threads:
        thread.start()
    assert run_match(spec, tmp_path, gc_network=False) == 0
    for thread in threads:
        thread.join(timeout=10)
    result = json.loads((tmp_path / "sim_result.json").read_text())
    cameras = result["cameras"]
    assert cameras["render_processes"] == (min(cpus, 4) if cpus >= 2 else 0)
    assert cameras["gl_backend"] == "osmesa" and cameras["frames"] >= 10
    assert len(images) >= 10
    assert all(len(image) == 320 * 240 * 3 for image in images)
    assert all(max(image) > 0 for image in images)  # not a black image from a failed worker
