"""The referee package depends on the standard library and numpy only."""

from __future__ import annotations

import subprocess
import sys


def test_referee_imports_only_stdlib_and_numpy() -> None:
    code = (
        "import sys, referee, referee.autoref, referee.net, referee.mirror, referee.rulebook;"
        "import referee.rules.ball_holding, referee.rules.pushing, referee.shootout;"
        "bad=[m for m in ('mujoco','docker','simulator','orchestrator','yaml','zenoh',"
        "'google.protobuf') if m in sys.modules];"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == ""
