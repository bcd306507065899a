"""A real lockstep match (referee, GameController, recording) in which one robot floods its
API port with small valid requests from a process of its own: the match keeps its pace and the
other team's robot its round trip, and the flooding robot is marked slow."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
from dataclasses import replace
from pathlib import Path
from typing import Any

from contracts.match_spec import MatchSpec
from simulator.runtime import run_match
from tests.integration.api.match_specs import short_spec
from tests.integration.api.test_api_runtime import _robot_loop


def _play(spec: MatchSpec, out: Path, *, flood: bool) -> dict[str, Any]:
    honest = threading.Thread(target=_robot_loop, args=(spec.blue.players[0].port, []))
    honest.start()
    flooder = None
    if flood:
        flooder = subprocess.Popen(
            [sys.executable, "-m", "testkit.flood_client", str(spec.red.players[0].port)],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
        )  # fmt: skip
    try:
        code = run_match(spec, out, gc_network=False)
    finally:
        if flooder is not None:
            flooder.kill()
            flooder.wait(timeout=10)
        honest.join(timeout=10)
    result: dict[str, Any] = json.loads((out / "sim_result.json").read_text())
    assert code == 0, f"the match ended with {code} (state {result.get('state')})"
    return result


def test_a_robot_flooding_its_port_does_not_starve_the_match(tmp_path: Path) -> None:
    spec = short_spec(stepping="lockstep")
    spec = replace(spec, timing=replace(spec.timing, half_duration_s=3.0,
                                        max_duration_real_s=90.0))  # fmt: skip
    calm = _play(spec, tmp_path / "calm", flood=False)
    flooded = _play(spec, tmp_path / "flooded", flood=True)
    assert flooded["state"] == "FINISHED"
    red, blue = flooded["robots"]["red-1"], flooded["robots"]["blue-1"]
    assert red["messages_in"] > 1000 and red["slow_periods"] >= 1  # it flooded; marked slow
    assert blue["slow_periods"] == 0
    # the match's pace and the honest robot's round trip, against the same match without
    # (loose: the two matches run minutes apart on a shared machine; the flood without its
    # budget made the match 3-50 times slower and the round trip 20-300 ms)
    rtf, calm_rtf = flooded["real_time_factor"], calm["real_time_factor"]
    assert rtf >= 0.3 * calm_rtf, (calm_rtf, rtf)
    calm_ms = calm["robots"]["blue-1"]["round_trip_ms"]["p50"]
    assert blue["round_trip_ms"]["p50"] <= 4 * calm_ms + 5.0, (calm_ms, blue["round_trip_ms"])
