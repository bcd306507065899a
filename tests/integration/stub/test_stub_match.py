"""The stub robot process against the real robot API server and a GameController on loopback.

The server steps the real MuJoCo world in lockstep (each step waits for the stub's answer) and
renders the head camera with the world's renderer, as in a match; the test plays the
GameController: it sends RGme packets to the stub and receives its RGrt ALIVE answers.
"""

from __future__ import annotations

import math
import os
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

import pytest

from contracts.gamecontroller import (
    GameControlData,
    RobotInfo,
    TeamInfo,
    decode_return,
    encode_game_state,
)
from contracts.ids import TeamColor
from referee.snapshot import PlaceBall
from simulator.api import LockstepSettings
from simulator.api.world_cameras import world_render_worker
from tests.integration.api.harness import RED1, free_ports, real_world, running_server

RED_TEAM = 7
BLUE_TEAM = 9


def rgme(state: int, packet: int) -> bytes:
    players = (RobotInfo(),) * 11
    return encode_game_state(
        GameControlData(
            packet_number=packet % 256,
            players_per_team=4,
            game_type=0,
            state=state,
            first_half=True,
            kick_off_team=RED_TEAM,
            secondary_state=0,
            secondary_state_info=(0, 0, 0, 0),
            secs_remaining=600,
            secondary_time=0,
            teams=(
                TeamInfo(team_number=BLUE_TEAM, team_colour=0, players=players),
                TeamInfo(team_number=RED_TEAM, team_colour=1, players=players),
            ),
        )
    )


@pytest.mark.slow
def test_stub_striker_connects_answers_the_gamecontroller_and_kicks(tmp_path: Path) -> None:
    os.environ.setdefault("MUJOCO_GL", "osmesa")
    world = real_world([RED1])  # red 1 stands at x = -1, facing +x
    world.apply(PlaceBall(position=(-0.45, -0.05, 0.07)))
    worker = world_render_worker(world)
    gc_data, gc_return = free_ports(2)
    answers = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    answers.bind(("127.0.0.1", gc_return))
    answers.settimeout(0.05)
    lockstep = LockstepSettings(deadline_s=2.0, time_bank_s=30.0)
    with running_server(robots=[RED1], world=world, worker=worker, lockstep=lockstep) as (
        driver,
        ports,
    ):
        env = {
            **os.environ,
            "ROBOCUP_ROBOT_ID": "1",
            "ROBOCUP_TEAM_COLOR": "red",
            "ROBOCUP_SIMULATOR_ADDR": f"127.0.0.1:{ports[RED1]}",
            "ROBOCUP_MIRROR_SERVER_IP": "127.0.0.1",
            "ROBOCUP_GAMECONTROLLER_IP": "127.0.0.1",
            "ROBOCUP_LOG_DIR": str(tmp_path),
        }
        argv = ["striker", "--start-pose", "-1", "0", "0"]
        argv += ["--gc-data-port", str(gc_data), "--gc-return-port", str(gc_return)]
        proc = subprocess.Popen(
            [sys.executable, "-m", "robot.stub", *argv], env=env, stderr=subprocess.DEVNULL
        )
        sender = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        ball = world.model.body("ball").id
        start = world.data.xpos[ball].copy()
        alive = 0
        moved = 0.0
        packet = 0
        try:
            deadline = time.monotonic() + 240
            while time.monotonic() < deadline and (moved < 0.5 or alive < 2):
                assert proc.poll() is None, "the stub exited"
                assert driver.error is None
                packet += 1
                sender.sendto(rgme(3, packet), ("127.0.0.1", gc_data))  # PLAYING
                try:
                    reply = decode_return(answers.recv(64))
                    assert (reply.team, reply.player) == (RED_TEAM, 1)
                    alive += 1
                except TimeoutError:
                    pass
                moved = math.dist(world.data.xpos[ball][:2], start[:2])
                time.sleep(0.2)
            assert alive >= 2, "no RGrt ALIVE from the stub"
            assert moved >= 0.5, f"ball moved {moved:.2f} m in {world.sim_time_ms / 1000} s"
            assert "red-1" in driver.server.connected()
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=20) == 0
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait()
            sender.close()
            answers.close()
    log = (tmp_path / "stub_red_1.log").read_text()
    assert "connected to the simulator" in log
    assert "kicking" in log
    assert TeamColor.RED.value in log
