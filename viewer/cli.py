"""``hlvs view`` and ``hlvs export`` (parsed in ``hlvs/commands/viewer.py``).

``view`` serves the viewer for replay files and match folders on 127.0.0.1 (no account, no
database) and prints one URL per page; ``export`` writes a replay as MCAP.
Exit codes: 0 done, 1 failed, 2 invalid input, 3 cannot listen, 130 interrupted.
"""

from __future__ import annotations

import socket
import sys
from pathlib import Path

from simulator import ReplayError
from viewer.errors import ExportError, SourceError


def view(*, paths: list[str], host: str, port: int) -> int:
    import uvicorn

    from viewer.api import create_app
    from viewer.sources import Catalog

    catalog = Catalog()
    pages: list[str] = []
    try:
        for path in paths:
            pages.extend(catalog.add_path(Path(path)))
    except SourceError as exc:
        print(f"hlvs view: {exc}", file=sys.stderr)
        return 2
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((host, port))
    except OSError as exc:
        print(f"hlvs view: cannot listen on {host}:{port}: {exc}", file=sys.stderr)
        return 3
    sock.listen(128)  # before the URLs are printed, so that opening one at once connects
    bound = sock.getsockname()[1]
    for page in pages:
        print(f"http://{host}:{bound}{page}", flush=True)
    config = uvicorn.Config(create_app(catalog), log_level="warning", lifespan="off")
    try:
        uvicorn.Server(config).run(sockets=[sock])
    except KeyboardInterrupt:
        return 130
    return 0


def export(*, replay: str, output: str, stats: str | None) -> int:
    from viewer.mcap_export import export_mcap

    try:
        summary = export_mcap(
            Path(replay), Path(output), stats_path=Path(stats) if stats else None
        )
    except (ReplayError, SourceError) as exc:
        print(f"hlvs export: {exc}", file=sys.stderr)
        return 2
    except ExportError as exc:
        print(f"hlvs export: {exc}", file=sys.stderr)
        return 1
    print(
        f"{output}: {summary['messages']} messages on {summary['channels']} channels, "
        f"{summary['duration_s']:.1f} s of simulated time"
    )
    return 0
