"""``hlvs bench actuators``: every servo of the league catalogue measured in the simulator
against its datasheet and Webots' motor model (:mod:`simulator.world.servo_tests` says how):
no-load speed and stall torque within 5 % of the datasheet, a position step with Webots'
default ``P = 10`` within 10 % of the analytic response, and the measured static friction and
backlash against the catalogue's figures. Prints one JSON document; exits 1 when a servo
misses its targets.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog=f"{os.environ.get('HLVS_PROG', 'python -m benchmarks.actuators')} bench actuators",
        description=__doc__.split("\n\n")[0] if __doc__ else None,
    )
    parser.add_argument(
        "--servo", action="append", default=[], metavar="ID",
        help="only this catalogue entry (MX-106@14.8V; repeatable; default: all)",
    )  # fmt: skip
    parser.add_argument("--json", action="store_true", help="print only the JSON document")
    args = parser.parse_args(argv)
    from simulator.world.servo_tests import SPEC_ERROR, STEP_ERROR, ServoReport, report
    from simulator.world.servos import find_servo, servo_ids

    chosen = args.servo or list(servo_ids())
    unknown = [name for name in chosen if find_servo(name) is None]
    if unknown:
        parser.error(
            f"--servo: {', '.join(unknown)} not in the catalogue ({', '.join(servo_ids())})"
        )
    started = time.perf_counter()
    servos: list[ServoReport] = []
    for name in chosen:
        entry = find_servo(name)
        assert entry is not None
        servos.append(report(entry))
    result = {
        "bench": "actuators",
        "targets": {"datasheet_error": SPEC_ERROR, "step_error": STEP_ERROR},
        "servos": servos,
        "wall_s": round(time.perf_counter() - started, 2),
        "ok": all(s["ok"] for s in servos),
    }
    print(json.dumps(result, indent=None if args.json else 2))
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
