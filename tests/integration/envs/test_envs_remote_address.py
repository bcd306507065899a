"""Environments over a remote simulator given by address: a real server process on loopback."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import gymnasium as gym
import numpy as np
import pytest

import envs  # noqa: F401
from envs import RemoteCrashed, RemoteError, TrainerError
from envs.remote import RemoteAddress, RemoteSession, parse_remotes
from envs.session_spec import SessionSpec


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def _start_server(unix: Path) -> tuple[subprocess.Popen[bytes], int]:
    port = _free_port()
    proc = subprocess.Popen(
        [sys.executable, "-m", "envs", "remote", "--host", "127.0.0.1", "--port", str(port),
         "--unix", str(unix)],  # fmt: skip
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
    )
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=1):
                break
        except OSError:
            time.sleep(0.1)
    else:
        proc.kill()
        pytest.fail("the remote server did not listen")
    time.sleep(0.2)  # the probe connection above is released
    return proc, port


@pytest.fixture
def remote(tmp_path: Path) -> Iterator[tuple[subprocess.Popen[bytes], int]]:
    proc, port = _start_server(tmp_path / "remote.sock")
    yield proc, port
    if proc.poll() is None:
        proc.send_signal(signal.SIGTERM)
        proc.wait(timeout=10)
    assert proc.stderr is not None
    proc.stderr.close()


def _episode(env: gym.Env, seed: int, steps: int) -> list[tuple[bytes, float]]:  # type: ignore[type-arg]
    rng = np.random.default_rng(seed)
    obs, _ = env.reset(seed=seed)
    out = [(obs["joints"].tobytes() + obs["perception"]["lines"].tobytes(), 0.0)]
    for _ in range(steps):
        obs, reward, *_ = env.step(rng.uniform(-0.1, 0.1, 20).astype(np.float32))
        out.append((obs["joints"].tobytes() + obs["forces"].tobytes(), float(reward)))
    return out


def test_remote_episode_equals_the_in_process_episode(
    remote: tuple[subprocess.Popen[bytes], int], tmp_path: Path
) -> None:
    _, port = remote
    env = gym.make("hlvs/Kick-v0", remotes=f"hlvs://127.0.0.1:{port}", perception=True)
    over_tcp = _episode(env, 11, 120)
    env.unwrapped.trainer.place_ball(1.0, 1.0)
    with pytest.raises(TrainerError):
        env.unwrapped.trainer.set_game_state("PLAYING")  # a skill session has no referee
    env.close()
    socket_url = f"hlvs+unix://{tmp_path / 'remote.sock'}"
    env = gym.make("hlvs/Kick-v0", remotes=socket_url, perception=True)
    over_unix = _episode(env, 11, 120)
    env.close()
    local = gym.make("hlvs/Kick-v0", perception=True)
    assert _episode(local, 11, 120) == over_tcp == over_unix
    local.close()


def test_match_over_a_remote_and_second_client_refused(
    remote: tuple[subprocess.Popen[bytes], int], tmp_path: Path
) -> None:
    _, port = remote
    env = gym.make("hlvs/Match-v0", remotes=f"hlvs://127.0.0.1:{port}", half_duration_s=5.0,
                   minimum_play_s=0.0)
    env.reset(seed=2)
    env.unwrapped.trainer.set_game_state("PLAYING")
    *_, info = env.step(np.zeros(20, np.float32))
    assert info["game"]["state"] == "PLAYING"
    with pytest.raises(RemoteError) as refused:
        RemoteSession(RemoteAddress("127.0.0.1", port), SessionSpec())
    assert "already serves" in str(refused.value)
    with pytest.raises(RemoteError) as refused:  # one client over both the port and the socket
        RemoteSession(parse_remotes(f"hlvs+unix://{tmp_path / 'remote.sock'}")[0], SessionSpec())
    assert "already serves" in str(refused.value)
    env.close()


def test_a_killed_remote_is_reported_with_its_cause(
    remote: tuple[subprocess.Popen[bytes], int],
) -> None:
    proc, port = remote
    env = gym.make("hlvs/Kick-v0", remotes=f"hlvs://127.0.0.1:{port}")
    env.reset(seed=1)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait(timeout=10)
    with pytest.raises(RemoteCrashed) as crashed:
        for _ in range(10):
            env.step(np.zeros(20, np.float32))
    assert crashed.value.address == f"hlvs://127.0.0.1:{port}"
    assert "connection" in crashed.value.cause
    with pytest.raises(RemoteError) as again:  # no pool started it: nothing to replace it with
        env.reset(seed=2)
    assert "crashed" in str(again.value)
    env.close()


def test_bad_addresses_are_refused_with_the_field() -> None:
    with pytest.raises(envs.EnvConfigError) as bad:
        parse_remotes("hlvs://nohost")
    assert bad.value.field == "remotes"
    assert parse_remotes("hlvs://a:1,b:2") == [RemoteAddress("a", 1), RemoteAddress("b", 2)]
    assert parse_remotes("hlvs+unix:///run/r.sock")[0].path == "/run/r.sock"
    with pytest.raises(envs.EnvConfigError) as bad:
        parse_remotes("hlvs+unix://relative.sock")
    assert "absolute" in bad.value.expected
    with pytest.raises(RemoteError) as refused:
        gym.make("hlvs/Kick-v0", remotes=f"hlvs://127.0.0.1:{_free_port()}")
    assert "cannot connect" in str(refused.value)


def _plain_episode(env: gym.Env, seed: int, steps: int) -> list[tuple[bytes, float, float]]:  # type: ignore[type-arg]
    rng = np.random.default_rng(seed)
    obs, info = env.reset(seed=seed)
    out = [(obs["joints"].tobytes(), 0.0, info["robot_to_ball_m"])]
    for _ in range(steps):
        obs, reward, _, _, info = env.step(rng.uniform(-0.1, 0.1, 20).astype(np.float32))
        out.append((obs["joints"].tobytes() + obs["forces"].tobytes(), float(reward),
                    info["kick_distance_m"]))  # fmt: skip
    return out


def test_compact_truth_frames_and_json_frames(
    remote: tuple[subprocess.Popen[bytes], int], tmp_path: Path
) -> None:
    """A client that asks for compact frames gets the truth as doubles (F) when there is
    nothing else to say, and the same episode as in-process; a client that does not (an
    older one) still gets JSON (T)."""
    from envs.wire import TAG_TRAINER, TAG_TRUTH, FrameReader, send_json

    url = f"hlvs+unix://{tmp_path / 'remote.sock'}"
    env = gym.make("hlvs/Kick-v0", remotes=url)
    assert env.unwrapped.session.compact
    remote_run = _plain_episode(env, 7, 80)
    env.close()
    local = gym.make("hlvs/Kick-v0")
    assert _plain_episode(local, 7, 80) == remote_run
    local.close()
    for compact, tag in ((False, TAG_TRAINER), (True, TAG_TRUTH)):
        time.sleep(0.2)  # the previous client is released
        with socket.socket(socket.AF_UNIX) as sock:
            sock.connect(str(tmp_path / "remote.sock"))
            assert sock.recv(8) == b"Welcome\0"
            reader = FrameReader(sock)
            opened = {"op": "open", "spec": SessionSpec().to_dict()}
            send_json(sock, {**opened, "compact": True} if compact else opened)
            assert reader.expect_json() == {"ok": True, "compact": compact}
            send_json(sock, {"op": "reset", "request": {"seed": 3}})
            assert reader.read()[0] == b"S" and reader.read()[0] == tag
            send_json(sock, {"op": "close"})
            assert reader.expect_json() == {"ok": True}
