"""``python -m simulator COMMAND``: run a match from a spec, render a replay, bench sim|api|stub.

Each command lives in its own module exposing ``main(argv) -> int``.
"""

from __future__ import annotations

import importlib
import sys

COMMANDS = {
    "run": "simulator.runtime",
    "render": "simulator.render",
    "remote": "envs.remote_server",  # learning sessions for remote environments
    "bench": None,
}
BENCHES = {
    "sim": "benchmarks.sim",
    "api": "benchmarks.api",
    "stub": "benchmarks.stub",
}

USAGE = "usage: python -m simulator {run|render|remote|bench sim|bench api|bench stub} ..."


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in COMMANDS:
        print(USAGE, file=sys.stderr)
        return 2
    if argv[0] == "bench":
        if len(argv) < 2 or argv[1] not in BENCHES:
            print(USAGE, file=sys.stderr)
            return 2
        module = BENCHES[argv[1]]
        rest = argv[2:]
    else:
        module = COMMANDS[argv[0]]  # type: ignore[assignment]
        rest = argv[1:]
    return int(importlib.import_module(module).main(rest))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
