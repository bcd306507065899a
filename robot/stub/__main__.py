"""``python -m robot.stub BEHAVIOUR``: the stub robot process (see robot.stub.runner)."""

from __future__ import annotations

import sys

from robot.stub.runner import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
