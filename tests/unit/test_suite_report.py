"""How a run of the suite ends (tests/conftest.py): past ``HLVS_TEST_DEADLINE`` with its report,
and with the machine's speed in it."""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

from tests.conftest import _machine_speed

REPO = Path(__file__).resolve().parents[2]

# The deadline is set once the tests are collected: pytest itself may take seconds to start.
CONFTEST = '''
import time

from tests.conftest import DEADLINE, pytest_runtest_protocol


def pytest_collection_finish(session):
    session.config.stash[DEADLINE] = time.time() + 10
'''

TESTS = '''
import time

def test_slow():
    time.sleep(60)

def test_after():
    pass
'''


def test_a_test_gets_the_time_left_and_none_starts_after_the_deadline(tmp_path: Path) -> None:
    (tmp_path / "conftest.py").write_text(CONFTEST)
    (tmp_path / "test_sample.py").write_text(TESTS)
    env = {name: value for name, value in os.environ.items() if name != "HLVS_TEST_DEADLINE"}
    env["PYTHONPATH"] = str(REPO)
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "-o", "timeout=600",
         "-rA", "--rootdir", str(tmp_path), str(tmp_path)],
        capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path, check=False)
    output = done.stdout + done.stderr
    assert "FAILED test_sample.py::test_slow" in output, output
    limit = re.search(r"Timeout \(>([0-9.]+)s\)", output)
    assert limit and float(limit.group(1)) <= 10.0, output  # the time left, not the ini's 600 s
    assert "PASSED test_sample.py::test_after" not in output, output
    assert "HLVS_TEST_DEADLINE passed" in output, output


def test_a_deadline_that_is_not_a_time_is_a_usage_error(tmp_path: Path) -> None:
    (tmp_path / "conftest.py").write_text(
        "from tests.conftest import pytest_configure, pytest_runtest_protocol\n")
    (tmp_path / "test_sample.py").write_text("def test_one():\n    pass\n")
    env = {**os.environ, "PYTHONPATH": str(REPO), "HLVS_TEST_DEADLINE": "tomorrow"}
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "--rootdir", str(tmp_path),
         str(tmp_path)],
        capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path, check=False)
    assert done.returncode != 0
    assert "HLVS_TEST_DEADLINE='tomorrow': expected seconds since the epoch" in (
        done.stdout + done.stderr)


def test_the_report_says_how_fast_the_machine_was() -> None:
    speed = _machine_speed()
    assert re.fullmatch(
        r"\d+ CPUs, load average [0-9.]+, [0-9.]+, [0-9.]+; a 2e6-step Python loop took "
        r"[0-9.]+ s \([0-9.]+ s of CPU\)(, \d+% of the CPUs' time stolen meanwhile)?", speed
    ), speed


def test_the_report_ends_with_the_set_up_times(tmp_path: Path) -> None:
    times = tmp_path / "setup-times.txt"
    times.write_text("venv 412 s\nimages 1290 s\n")
    (tmp_path / "conftest.py").write_text(
        "from tests.conftest import pytest_configure, pytest_terminal_summary\n")
    (tmp_path / "test_sample.py").write_text("def test_one():\n    pass\n")
    env = {name: value for name, value in os.environ.items() if name != "HLVS_TEST_DEADLINE"}
    env.update(PYTHONPATH=str(REPO), HLVS_SETUP_TIMES=str(times))
    done = subprocess.run(
        [sys.executable, "-m", "pytest", "-p", "no:cacheprovider", "--rootdir", str(tmp_path),
         str(tmp_path)],
        capture_output=True, text=True, timeout=300, env=env, cwd=tmp_path, check=False)
    assert done.returncode == 0, done.stdout + done.stderr
    assert "set-up before the tests: venv 412 s, images 1290 s\n" in done.stdout, done.stdout
    assert "machine at the end: " in done.stdout, done.stdout
