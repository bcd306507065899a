"""The stub robot as a process: signals, crash-after, fill-logs (no simulator is listening)."""

from __future__ import annotations

import os
import signal
import socket
import subprocess
import sys
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest


def _closed_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


@contextmanager
def stub(tmp_path: Path, *argv: str, port: int | None = None
         ) -> Iterator[subprocess.Popen[str]]:
    env = {
        **os.environ,
        "ROBOCUP_ROBOT_ID": "1",
        "ROBOCUP_TEAM_COLOR": "red",
        "ROBOCUP_SIMULATOR_ADDR": f"127.0.0.1:{port or _closed_port()}",
        "ROBOCUP_MIRROR_SERVER_IP": "127.0.0.1",
        "ROBOCUP_LOG_DIR": str(tmp_path / "logs"),
    }
    ports = ["--gc-data-port", str(_closed_port()), "--gc-return-port", str(_closed_port())]
    proc = subprocess.Popen(
        [sys.executable, "-m", "robot.stub", *argv, *ports],
        env=env,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        yield proc
    finally:
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=10)
        if proc.stderr is not None:
            proc.stderr.close()


def wait_for_log(tmp_path: Path, text: str, timeout_s: float = 30.0) -> str:
    path = tmp_path / "logs" / "stub_red_1.log"
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        if path.exists() and text in (content := path.read_text()):
            return content
        time.sleep(0.05)
    raise AssertionError(f"{text!r} not in {path} after {timeout_s} s")


def test_sigterm_exits_zero(tmp_path: Path) -> None:
    with stub(tmp_path, "striker") as proc:
        wait_for_log(tmp_path, "not available")
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=15) == 0
    assert "received SIGTERM" in (tmp_path / "logs" / "stub_red_1.log").read_text()


def test_sigterm_during_a_connect_that_hangs_exits_within_the_grace(tmp_path: Path) -> None:
    """An address that answers nothing (the simulator's container gone at the end of a match;
    here a listening socket whose backlog is full, so connects hang): each connect gives up
    after a second, so a stop signal is heeded well within the league's 5 s grace."""
    with socket.socket() as full:
        full.bind(("127.0.0.1", 0))
        full.listen(0)
        held = socket.create_connection(full.getsockname(), timeout=1.0)  # fills the backlog
        try:
            with stub(tmp_path, "striker", port=int(full.getsockname()[1])) as proc:
                wait_for_log(tmp_path, "not available")  # one connect timed out
                time.sleep(0.3)  # most likely in the next one
                sent = time.monotonic()
                proc.send_signal(signal.SIGTERM)
                assert proc.wait(timeout=15) == 0
                assert time.monotonic() - sent < 2.5
        finally:
            held.close()
    log = (tmp_path / "logs" / "stub_red_1.log").read_text()
    assert "timed out" in log and "received SIGTERM" in log


def test_ignore_sigterm_survives_sigterm(tmp_path: Path) -> None:
    with stub(tmp_path, "ignore-sigterm") as proc:
        wait_for_log(tmp_path, "ignoring SIGTERM")
        proc.send_signal(signal.SIGTERM)
        with pytest.raises(subprocess.TimeoutExpired):
            proc.wait(timeout=1.5)
        proc.kill()
        assert proc.wait(timeout=10) == -signal.SIGKILL


def test_crash_after_exits_non_zero_after_the_time(tmp_path: Path) -> None:
    start = time.monotonic()
    with stub(tmp_path, "crash-after", "1.5") as proc:
        code = proc.wait(timeout=30)
    elapsed = time.monotonic() - start
    assert code != 0
    assert elapsed >= 1.5
    assert "crash-after" in (tmp_path / "logs" / "stub_red_1.log").read_text()


def test_fill_logs_stops_at_the_cap_and_keeps_running(tmp_path: Path) -> None:
    cap = 3 * 1024 * 1024 + 123
    with stub(tmp_path, "fill-logs", "--fill-cap-bytes", str(cap)) as proc:
        wait_for_log(tmp_path, "fill-logs stopped")
        assert (tmp_path / "logs" / "fill.log").stat().st_size == cap
        assert proc.poll() is None  # still running
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=15) == 0


def test_bad_environment_exits_2_with_the_variable(tmp_path: Path) -> None:
    env = {k: v for k, v in os.environ.items() if not k.startswith("ROBOCUP_")}
    env["ROBOCUP_ROBOT_ID"] = "1"
    result = subprocess.run(
        [sys.executable, "-m", "robot.stub", "striker"],
        env=env,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert result.returncode == 2
    assert "ROBOCUP_TEAM_COLOR" in result.stderr
    assert "Traceback" not in result.stderr


@pytest.mark.root
def test_fill_logs_fills_a_small_disk_and_keeps_running(tmp_path: Path) -> None:
    disk = tmp_path / "logs"
    disk.mkdir()
    mounted = subprocess.run(
        ["mount", "-t", "tmpfs", "-o", "size=4m", "tmpfs", str(disk)], capture_output=True
    )
    if mounted.returncode != 0:
        pytest.skip(f"cannot mount a tmpfs: {mounted.stderr.decode().strip()}")
    try:
        with stub(tmp_path, "fill-logs") as proc:
            deadline = time.monotonic() + 30
            while time.monotonic() < deadline:
                stats = os.statvfs(disk)
                if stats.f_bavail * stats.f_frsize < 64 * 1024:
                    break
                time.sleep(0.05)
            else:
                raise AssertionError("the log disk never filled up")
            time.sleep(1.0)
            assert proc.poll() is None  # still running with a full disk
            proc.send_signal(signal.SIGTERM)
            assert proc.wait(timeout=15) == 0
            assert (disk / "fill.log").stat().st_size > 3 * 1024 * 1024
    finally:
        subprocess.run(["umount", str(disk)], check=False)
