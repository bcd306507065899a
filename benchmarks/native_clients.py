"""``bench api --native``: the bench's robot clients as compiled code (``native/bench_client.c``).

The bench machine's clients share CPUs with the server they measure. A Python client costs
about 30 us of CPU per measurement between its two socket calls; eight of them on one CPU keep a
lockstep server waiting about 0.25 ms a step whatever the server does: on our 2-CPU machine a C
server stepping a 1070 us busy loop in place of the world reached 0.76-0.78 of the loop's speed
against eight Python clients and 0.83-0.86 against eight of these. The league's own test client
is compiled C++, as most teams' code is.

The client is built once per source version with the machine's C compiler (``$CC``, else
``cc``) into the user's cache; a machine without one gets a clear error naming what to install.
"""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

from simulator import native_build

NATIVE = Path(__file__).with_name("native")
SOURCE = NATIVE / "bench_client.c"
FLOOR_SOURCE = NATIVE / "lockstep_floor.c"
STYLES = ("framed", "league")


def compiler() -> str | None:
    """The C compiler the clients are built with: ``$CC``, else ``cc`` or ``gcc`` on the path."""
    return native_build.compiler()


def binary(source_path: Path = SOURCE) -> Path:
    """The compiled client (or another of ``native/``), built now if this source version has
    not been."""
    try:
        return native_build.build_native(source_path, "bench")
    except native_build.NativeBuildError as exc:
        raise SystemExit(f"bench api --native: {exc.reason}") from exc


def frames_file(directory: Path, welcome: bytes, enable: bytes, answers: Sequence[bytes]) -> Path:
    """The client's frames: the server's greeting, the framed request that enables the sensors
    and the framed answers (each a 4-byte big-endian length and a body)."""
    if len(welcome) != 8:
        raise ValueError("the greeting is 8 bytes")
    for frame in (enable, *answers):
        if int.from_bytes(frame[:4], "big") != len(frame) - 4:
            raise ValueError("each frame is its 4-byte big-endian length and its body")
    path = directory / "frames.bin"
    path.write_bytes(welcome + enable + b"".join(answers))
    return path


def start(
    program: Path, port: int, frames: Path, style: str, cpus: Iterable[int] = ()
) -> subprocess.Popen[bytes]:
    """One robot's client process on ``port``; ``style`` "framed" (``TCP_NODELAY``, one write
    a request) or "league" (no ``TCP_NODELAY``, the length and the body in two writes)."""
    if style not in STYLES:
        raise ValueError(f"style {style!r}: expected one of {', '.join(STYLES)}")
    command = [str(program), str(port), str(frames), style]
    if cpus:
        command.append(",".join(str(cpu) for cpu in sorted(cpus)))
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE)


def figures(client: subprocess.Popen[bytes]) -> list[tuple[int, float | None, float | None]]:
    """Wait for a client that the server closed and read what it printed: [(answers, median
    of answer_s, median of round_trip_s)] (seconds), or [] when it printed nothing (killed
    after 10 s: it did not end)."""
    try:
        out, _ = client.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        client.kill()
        client.communicate()
        return []
    try:
        printed = json.loads(out.decode().strip().splitlines()[-1])
    except (IndexError, ValueError):
        return []
    return [(printed["answered"], printed["answer_s"], printed["round_trip_s"])]


def lockstep_floor(
    frames: Path, style: str, *, robots: int, step_us: float, measurement_bytes: int,
    steps: int, server_cpu: int | None, client_cpus: Iterable[int] = (),
) -> dict[str, Any]:
    """Lockstep's serial floor on this machine (``native/lockstep_floor.c``): a C server that
    busy-loops ``step_us`` in place of the world, then sends each of ``robots`` compiled clients
    (``frames``, ``style``) a measurement of ``measurement_bytes`` and waits for every answer.
    Its ratio of busy to wall time is what no lockstep server that sends and reads on its step
    thread can pass with these clients here; the JSON the floor printed."""
    from simulator.api.endpoints import free_ports

    floor = binary(FLOOR_SOURCE)
    client = binary()
    welcome = frames.read_bytes()[:8]
    (port,) = free_ports(1)
    command = [str(floor), str(port), str(robots), str(steps), f"{step_us:.1f}",
               str(measurement_bytes), welcome.hex()]  # fmt: skip
    if server_cpu is not None:
        command.append(str(server_cpu))
    server = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    clients = [start(client, port, frames, style, client_cpus) for _ in range(robots)]
    try:
        out, err = server.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        server.kill()
        out, err = server.communicate()
    finally:
        for proc in clients:
            figures(proc)
    if server.returncode != 0 or not out.strip():
        return {"error": f"lockstep floor: exit code {server.returncode}: {err.strip()[-200:]}"}
    result: dict[str, Any] = json.loads(out.strip().splitlines()[-1])
    return result
