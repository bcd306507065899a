"""A robot-side parser, written from the published packet layout, follows a real match.

The simulator process plays a short match and sends ``RGme`` to the robots' addresses
(127.0.0.21 and 127.0.0.22 stand for the two robots); the client library's listener decodes
state, score, seconds remaining and the robot's own penalty. Garbage sent to the return port
(3939's stand-in) and to the team mirror is ignored and counted.
"""

from __future__ import annotations

import re
import socket
import subprocess
import sys
import threading
import time
from dataclasses import replace
from pathlib import Path

from contracts.match_spec import MatchSpec
from robot.client import GameControllerListener
from robot.client.gamecontroller import GameControlData, GameState
from tests.integration.api.match_specs import short_spec

ROBOTS = {"red": "127.0.0.21", "blue": "127.0.0.22"}


def _spec() -> MatchSpec:
    spec = short_spec(players=1, stepping="async")
    red = replace(spec.red, robot_addresses=(ROBOTS["red"],), hosts=("127.0.0.1", ROBOTS["red"]))
    blue = replace(
        spec.blue, robot_addresses=(ROBOTS["blue"],), hosts=("127.0.0.1", ROBOTS["blue"])
    )
    timing = replace(spec.timing, half_duration_s=3.0, wait_before_first_ready_real_s=1.0)
    return replace(spec, red=red, blue=blue, timing=timing, maximum_real_time_factor=2.0)


def _listen(
    listener: GameControllerListener, seen: list[GameControlData], stop: threading.Event
) -> None:
    while not stop.is_set():
        packet = listener.receive(timeout=0.2)
        if packet is not None:
            seen.append(packet)


def test_robot_side_parser_follows_a_real_match_and_garbage_is_counted(tmp_path: Path) -> None:
    spec = _spec()
    port = spec.network.gc_data_port
    listeners = {c: GameControllerListener(host=ip, port=port) for c, ip in ROBOTS.items()}
    seen: dict[str, list[GameControlData]] = {c: [] for c in ROBOTS}
    stop = threading.Event()
    threads = [threading.Thread(target=_listen, args=(listeners[c], seen[c], stop)) for c in ROBOTS]
    for thread in threads:
        thread.start()
    out = tmp_path / "out"
    spec_path = tmp_path / "spec.json"
    spec_path.write_text(spec.to_json())
    proc = subprocess.Popen(
        [sys.executable, "-m", "simulator", "run", "--spec", str(spec_path), "--out", str(out)],
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 60
        while not seen["red"] and time.monotonic() < deadline:
            time.sleep(0.05)
        assert seen["red"], "no GameController packet reached the red robot"
        robot = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        robot.bind((ROBOTS["red"], 0))
        stranger = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        stranger.bind(("127.0.0.99", 0))
        for payload in (b"", b"RGrt", b"\xff" * 8, b"RGme" + bytes(684), b"garbage" * 10):
            robot.sendto(payload, ("127.0.0.1", spec.network.gc_return_port))
        stranger.sendto(b"hello team", ("127.0.0.1", spec.network.mirror_port))
        robot.close()
        stranger.close()
        _, stderr = proc.communicate(timeout=120)
    finally:
        if proc.poll() is None:
            proc.kill()
        stop.set()
        for thread in threads:
            thread.join(timeout=5)
        for listener in listeners.values():
            listener.close()
    assert proc.returncode == 0, stderr[-2000:]

    for color, team_id in (("red", spec.red.team_id), ("blue", spec.blue.team_id)):
        packets = seen[color]
        states = [p.state for p in packets]
        order = [s for i, s in enumerate(states) if i == 0 or s != states[i - 1]]
        for state in (GameState.READY, GameState.SET, GameState.PLAYING, GameState.FINISHED):
            assert state in order, (color, order)
        assert order.index(GameState.READY) < order.index(GameState.PLAYING)
        assert order[-1] is GameState.FINISHED
        playing = [p.secs_remaining for p in packets if p.state is GameState.PLAYING]
        assert max(playing) > min(playing), "secsRemaining never moved while PLAYING"
        last = packets[-1]
        assert last.score(team_id) == 0 and last.score(spec.red.team_id + 1000) is None
        assert last.own_penalty(team_id, 1) == 0
        assert last.players_per_team == 4

    log = (out / "gamecontroller.log").read_text()
    garbage = [int(n) for n in re.findall(r"garbage: (\d+)", log)]
    assert garbage and garbage[-1] >= 4, log[-2000:]
    assert "unknown host 127.0.0.99" in (out / "bouncing_log.txt").read_text()
