"""``hlvs view`` and ``hlvs export``: the web viewer and the MCAP export (package ``viewer``)."""

from __future__ import annotations

import argparse
import logging
from typing import Any

from orchestrator import user_path


def register(sub: Any) -> None:
    view: argparse.ArgumentParser = sub.add_parser(
        "view",
        help="serve the 3D replay viewer (and the live view of a running match) on 127.0.0.1",
    )
    view.add_argument(
        "paths", nargs="+", type=user_path, metavar="MATCH_DIR|REPLAY",
        help="match folders (as hlvs match / scrimmage write them) or .hlvsrec replay files",
    )  # fmt: skip
    view.add_argument(
        "--host", default="127.0.0.1", help="address to listen on (default 127.0.0.1)"
    )
    view.add_argument("--port", type=int, default=0, help="port (default: a free one)")
    view.set_defaults(func=_view, log_level=logging.INFO)
    export: argparse.ArgumentParser = sub.add_parser(
        "export", help="export a replay to MCAP (Foxglove schemas, simulated time)"
    )
    export.add_argument("replay", type=user_path, metavar="REPLAY", help="the .hlvsrec replay file")
    export.add_argument("-o", "--output", type=user_path, required=True, help="MCAP file to write")
    export.add_argument(
        "--stats", type=user_path,
        help="api_stats.jsonl to include (default: the one beside the replay)",
    )
    export.set_defaults(func=_export)


def _view(args: argparse.Namespace) -> int:
    from viewer import view

    return view(paths=[str(p) for p in args.paths], host=args.host, port=args.port)


def _export(args: argparse.Namespace) -> int:
    from viewer import export

    return export(
        replay=str(args.replay), output=str(args.output),
        stats=str(args.stats) if args.stats else None,
    )
