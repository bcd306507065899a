"""``hlvs view`` and ``hlvs export``: argument handling and exit codes for the viewer package.

``hlvs view PATH...`` serves the viewer for replay files and match folders on 127.0.0.1 (no
account, no database) and prints one URL per page; ``hlvs export REPLAY -o match.mcap``
writes the replay as MCAP.
"""

from __future__ import annotations

import argparse
import logging
import socket
import sys
from pathlib import Path

from simulator.errors import ReplayError
from viewer.errors import ExportError, SourceError

log = logging.getLogger(__name__)


def view(args: argparse.Namespace) -> int:
    import uvicorn

    from viewer.api import create_app
    from viewer.sources import Catalog

    catalog = Catalog()
    pages: list[str] = []
    try:
        for path in args.paths:
            pages.extend(catalog.add_path(Path(path)))
    except SourceError as exc:
        print(f"hlvs view: {exc}", file=sys.stderr)
        return 2
    sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
    try:
        sock.bind((args.host, args.port))
    except OSError as exc:
        print(f"hlvs view: cannot listen on {args.host}:{args.port}: {exc}", file=sys.stderr)
        return 3
    port = sock.getsockname()[1]
    for page in pages:
        print(f"http://{args.host}:{port}{page}", flush=True)
    config = uvicorn.Config(create_app(catalog), log_level="warning", lifespan="off")
    try:
        uvicorn.Server(config).run(sockets=[sock])
    except KeyboardInterrupt:
        return 130
    return 0


def export(args: argparse.Namespace) -> int:
    from viewer.mcap_export import export_mcap

    stats = Path(args.stats) if args.stats else None
    try:
        summary = export_mcap(Path(args.replay), Path(args.output), stats_path=stats)
    except (ReplayError, SourceError) as exc:
        print(f"hlvs export: {exc}", file=sys.stderr)
        return 2
    except ExportError as exc:
        print(f"hlvs export: {exc}", file=sys.stderr)
        return 1
    print(
        f"{args.output}: {summary['messages']} messages on {summary['channels']} channels, "
        f"{summary['duration_s']:.1f} s of simulated time"
    )
    return 0


def add_view_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("paths", nargs="+", metavar="MATCH_DIR|REPLAY")
    parser.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)"
    )
    parser.add_argument("--port", type=int, default=0, help="port (default: a free one)")


def add_export_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("replay", metavar="REPLAY")
    parser.add_argument("-o", "--output", required=True, help="MCAP file to write")
    parser.add_argument(
        "--stats", help="api_stats.jsonl to include (default: the one beside the replay)"
    )
