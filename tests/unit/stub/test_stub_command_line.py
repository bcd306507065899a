"""The stub robot's own command line: ``--help`` prints its options and exits 0; a missing or
corrupt ``--kick-policy`` file is one line on stderr and exit 2, never a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from robot.stub.runner import main

REPO = Path(__file__).parents[3]
ROBOT_ENV = {"ROBOCUP_ROBOT_ID": "1", "ROBOCUP_TEAM_COLOR": "red",
             "ROBOCUP_SIMULATOR_ADDR": "127.0.0.1:9"}


def test_help_prints_the_options_and_exits_0() -> None:
    done = subprocess.run([sys.executable, "-m", "robot.stub", "--help"], cwd=REPO,
                          capture_output=True, text=True, timeout=60, check=False)
    assert done.returncode == 0, done.stderr
    assert done.stdout.startswith("usage: python -m robot.stub")
    assert "--kick-policy FILE" in done.stdout and "striker, goalie" in done.stdout


@pytest.mark.parametrize(("content", "says"), [
    (None, "expected an existing file"),
    (b"{not a policy", "not a .npz archive"),
    (b"PK\x03\x04broken zip", "not readable as one"),
])
def test_a_missing_or_corrupt_policy_file_is_one_line(
        content: bytes | None, says: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    for name, value in ROBOT_ENV.items():
        monkeypatch.setenv(name, value)
    policy = tmp_path / "kick.npz"
    if content is not None:
        policy.write_bytes(content)
    assert main(["striker", "--kick-policy", str(policy)]) == 2
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"stub robot: --kick-policy: got {str(policy)!r}")
    assert says in lines[0]
