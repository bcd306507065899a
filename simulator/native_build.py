"""Small C programs built once per source version with the machine's C compiler into the user's
cache: plain lockstep's exchange thread (:mod:`simulator.api.exchange`, a shared library), the
robots' start gate (:mod:`orchestrator.match.gate`) and the benchmarks' compiled clients
(``benchmarks/native_clients.py``)."""

from __future__ import annotations

import hashlib
import os
import shutil
import subprocess
import tempfile
from collections.abc import Sequence
from pathlib import Path


class NativeBuildError(Exception):
    """The program could not be built here (``reason`` says why, for the caller's message)."""

    def __init__(self, reason: str) -> None:
        self.reason = reason
        super().__init__(reason)


def cache_dir(name: str) -> Path:
    """``$XDG_CACHE_HOME/hlvs/<name>`` (default ``~/.cache``)."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "hlvs" / name


def compiler() -> str | None:
    """The C compiler: ``$CC``, else ``cc`` or ``gcc`` on the path."""
    return os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")


def build_native(source_path: Path, cache: str, flags: Sequence[str] = ("-O2",)) -> Path:
    """The program compiled from ``source_path`` with ``flags`` into :func:`cache_dir`
    ``(cache)``, named by a hash of the source; built now if this version has not been.

    Raises:
        NativeBuildError: no compiler, it failed, or the cache cannot be written."""
    source = source_path.read_bytes()
    built = cache_dir(cache) / f"{source_path.stem}-{hashlib.sha256(source).hexdigest()[:16]}"
    if built.is_file() and os.access(built, os.X_OK):
        return built
    compiler_path = compiler()
    if not compiler_path:
        raise NativeBuildError("no C compiler (set CC or install one, e.g. apt-get install gcc)")
    try:
        built.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=built.parent) as work:
            partial = Path(work) / built.name
            done = subprocess.run(
                [compiler_path, *flags, "-o", str(partial), str(source_path)],
                capture_output=True, text=True, check=False, timeout=120,
            )  # fmt: skip
            if done.returncode != 0:
                raise NativeBuildError(f"{compiler_path} could not build {source_path.name}:\n"
                                       f"{done.stderr.strip()}")
            partial.chmod(0o755)
            os.replace(partial, built)  # whole or not at all, when two builds run at once
    except (OSError, subprocess.SubprocessError) as exc:
        raise NativeBuildError(f"{source_path.name} could not be built in {built.parent}: "
                               f"{exc}") from exc
    return built


__all__ = ["NativeBuildError", "build_native", "cache_dir", "compiler"]
