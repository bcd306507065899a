"""``python -m envs remote ...``: the server of remote environments (the simulator image runs it
for ``envs.DockerPool``). Their benchmark is ``python -m benchmarks envs`` (``hlvs bench envs``)."""

from __future__ import annotations

import sys

USAGE = "usage: python -m envs remote ..."


def main(argv: list[str]) -> int:
    if not argv or argv[0] != "remote":
        print(USAGE, file=sys.stderr)
        return 2
    from envs import remote_server

    return int(remote_server.main(argv[1:]))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
