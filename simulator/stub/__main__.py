"""``python -m simulator.stub BEHAVIOUR``: the stub robot process (see simulator.stub.runner)."""

from __future__ import annotations

import sys

from simulator.stub.runner import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
