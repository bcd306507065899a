"""One way to start ``hlvs match``: :func:`cluster.start_match`, used by the local pool (the
child in a session of its own, so that it outlives a restarted service) and by the tournament
scheduler (the child stays in the scheduler's session and gets SIGTERM if the scheduler
dies)."""

from __future__ import annotations

import os
import stat
import time
from pathlib import Path

import pytest

from cluster import start_match


def _fake_python(tmp_path: Path) -> Path:
    """Stands for the interpreter: writes its arguments, then waits to be stopped."""
    fake = tmp_path / "python"
    fake.write_text(f'#!/bin/sh\necho "$@" > {tmp_path / "argv"}\nexec sleep 60\n')
    fake.chmod(fake.stat().st_mode | stat.S_IXUSR)
    return fake


def _argv(tmp_path: Path) -> str:
    deadline = time.monotonic() + 10
    while not (tmp_path / "argv").is_file() or not (tmp_path / "argv").read_text():
        assert time.monotonic() < deadline, "the child never wrote its arguments"
        time.sleep(0.02)
    return (tmp_path / "argv").read_text().strip()


@pytest.mark.parametrize("own_session", [True, False])
def test_the_child_runs_hlvs_match_in_the_session_asked_for(
    tmp_path: Path, own_session: bool
) -> None:
    with open(tmp_path / "log", "ab") as output:
        child = start_match(tmp_path / "game.json", tmp_path / "out", output,
                            python=str(_fake_python(tmp_path)), hlvs_args=("--verbose",),
                            match_args=("--grace", "3"), own_session=own_session,
                            die_with_parent=not own_session)
    try:
        assert _argv(tmp_path) == (f"-m hlvs --verbose match {tmp_path / 'game.json'} "
                                   f"--out {tmp_path / 'out'} --grace 3")
        assert (os.getsid(child.pid) == child.pid) is own_session
        assert (os.getsid(child.pid) == os.getsid(0)) is not own_session
    finally:
        child.terminate()
        child.wait(timeout=10)


def test_a_child_that_cannot_start_raises_oserror(tmp_path: Path) -> None:
    with open(tmp_path / "log", "ab") as output, pytest.raises(OSError):
        start_match(tmp_path / "game.json", tmp_path / "out", output,
                    python=str(tmp_path / "no-such-python"))
