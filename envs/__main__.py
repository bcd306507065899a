"""``python -m envs bench ...`` (also ``hlvs bench envs``), ``python -m envs remote ...``."""

from __future__ import annotations

import importlib
import sys

COMMANDS = {"bench": "benchmarks.envs", "remote": "envs.remote_server"}
USAGE = "usage: python -m envs {bench|remote} ..."


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in COMMANDS:
        print(USAGE, file=sys.stderr)
        return 2
    return int(importlib.import_module(COMMANDS[argv[0]]).main(argv[1:]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
