"""The bench's compiled programs (``benchmarks/native``) on bad input: each names what it was
given and what it expected, and exits 2, before it touches a socket."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

NATIVE = Path(__file__).resolve().parents[3] / "benchmarks" / "native"
WELCOME = b"Welcome\0"


@pytest.fixture(scope="module")
def built(tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    compiler = shutil.which("cc") or shutil.which("gcc")
    assert compiler, "no C compiler: make setup installs gcc"
    out = tmp_path_factory.mktemp("native")
    programs = {}
    for source in sorted(NATIVE.glob("*.c")):
        program = out / source.stem
        command = [compiler, "-O2", "-Wall", "-Wextra", "-Werror", "-o", str(program), str(source)]
        done = subprocess.run(command, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        programs[source.stem] = program
    assert set(programs) == {"bench_client", "lockstep_floor"}
    return programs


def _frame(body: bytes) -> bytes:
    return len(body).to_bytes(4, "big") + body


def test_the_client_refuses_a_frames_file_whose_frame_runs_past_its_end(
    built: dict[str, Path], tmp_path: Path
) -> None:
    frames = tmp_path / "frames.bin"
    frames.write_bytes(WELCOME + _frame(b"enable") + (100).to_bytes(4, "big") + b"short")
    done = subprocess.run([str(built["bench_client"]), "1", str(frames), "framed"],
                          capture_output=True, text=True, timeout=10)  # fmt: skip
    assert done.returncode == 2
    assert f"{frames}: a frame runs past the end at byte 18" in done.stderr


def test_the_client_needs_an_answer_and_a_known_style(
    built: dict[str, Path], tmp_path: Path
) -> None:
    frames = tmp_path / "frames.bin"
    frames.write_bytes(WELCOME + _frame(b"enable"))
    done = subprocess.run([str(built["bench_client"]), "1", str(frames), "framed"],
                          capture_output=True, text=True, timeout=10)  # fmt: skip
    assert done.returncode == 2 and "needs the enable request and an answer" in done.stderr
    done = subprocess.run([str(built["bench_client"]), "1", str(frames), "chatty"],
                          capture_output=True, text=True, timeout=10)  # fmt: skip
    assert done.returncode == 2 and "bad port 1 or style chatty" in done.stderr


def test_the_floor_refuses_arguments_out_of_range(built: dict[str, Path]) -> None:
    done = subprocess.run([str(built["lockstep_floor"]), "0", "8", "100", "1000", "500",
                           WELCOME.hex()], capture_output=True, text=True, timeout=10)  # fmt: skip
    assert done.returncode == 2 and "an argument is out of range" in done.stderr
    done = subprocess.run([str(built["lockstep_floor"]), "5000", "8"], capture_output=True,
                          text=True, timeout=10)  # fmt: skip
    assert done.returncode == 2 and "usage: lockstep_floor" in done.stderr
