"""The five-node Slurm cluster on this machine (scripts/ensure-slurm.sh, idempotent)."""

from __future__ import annotations

import os
import shutil
import subprocess
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
CONF = "/var/lib/hlvs/slurm/slurm.conf"


@pytest.fixture(scope="session")
def cluster() -> Iterator[str]:
    if os.geteuid() != 0 or shutil.which("apt-get") is None:
        pytest.skip("the Slurm cluster needs root on Debian")
    result = subprocess.run(["bash", str(ROOT / "scripts" / "ensure-slurm.sh"), "up"],
                            capture_output=True, text=True, timeout=600, check=False)
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-2000:]
    yield CONF
