"""``python -m simulator COMMAND``: run a match from a spec (``run``) or render a replay
(``render``). Each command lives in its own module exposing ``main(argv) -> int``.

The simulator's benchmarks are ``python -m benchmarks sim|api|stub`` (``hlvs bench ...``) and
the remote environments' server is ``python -m envs remote``: both sit above the simulator.
"""

from __future__ import annotations

import sys

USAGE = "usage: python -m simulator {run|render} ..."


def main(argv: list[str]) -> int:
    if not argv or argv[0] not in ("run", "render"):
        print(USAGE, file=sys.stderr)
        return 2
    if argv[0] == "run":
        from simulator import runtime

        return int(runtime.main(argv[1:]))
    from simulator import render

    return int(render.main(argv[1:]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
