"""``hlvs view`` and ``hlvs export``: the web viewer and the MCAP export (package ``viewer``)."""

from __future__ import annotations

from typing import Any


def register(sub: Any) -> None:
    from viewer.cli import add_export_arguments, add_view_arguments, export, view

    parser = sub.add_parser(
        "view", help="serve the replay / live viewer for match folders or replays on 127.0.0.1"
    )
    add_view_arguments(parser)
    parser.set_defaults(func=view)
    parser = sub.add_parser("export", help="export a replay to MCAP (Foxglove schemas)")
    add_export_arguments(parser)
    parser.set_defaults(func=export)
