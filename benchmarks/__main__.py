"""``python -m benchmarks KIND ...``: the benchmarks that run in a process of their own
(``hlvs bench sim|api|stub`` execute this, with ``HLVS_PROG=hlvs`` so that their parsers name
themselves ``hlvs bench``). Each prints JSON."""

from __future__ import annotations

import sys

USAGE = "usage: python -m benchmarks {sim|api|stub|envs|video} ..."


def main(argv: list[str]) -> int:
    kind, rest = (argv[0], argv[1:]) if argv else ("", [])
    if kind == "sim":
        from benchmarks import sim

        return int(sim.main(rest))
    if kind == "api":
        from benchmarks import api

        return int(api.main(rest))
    if kind == "stub":
        from benchmarks import stub

        return int(stub.main(rest))
    if kind == "envs":
        from benchmarks import envs

        return int(envs.main(rest))
    if kind == "video":
        from benchmarks import video

        return int(video.main(rest))
    print(USAGE, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
