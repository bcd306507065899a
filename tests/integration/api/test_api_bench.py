"""``python -m benchmarks api`` end to end, small: real clients, one JSON line."""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest


def _bench(*args: str) -> dict[str, object]:
    proc = subprocess.run(
        [sys.executable, "-m", "benchmarks", "api", "--robots", "2", *args, "--json"],
        capture_output=True,
        text=True,
        timeout=180,
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    result: dict[str, object] = json.loads(proc.stdout.strip().splitlines()[-1])
    return result


@pytest.mark.parametrize("mode", ["lockstep", "pipelined"])
def test_bench_api_lockstep_reports_every_figure(mode: str) -> None:
    result = _bench("--mode", mode, "--sim-seconds", "0.5")
    assert result["bench"] == "api" and result["mode"] == mode
    wait_share = result["client_wait_share"]
    assert isinstance(wait_share, float) and 0 <= wait_share < 1
    interleaved = result["ratio_interleaved"]
    assert isinstance(interleaved, float) and interleaved > 0
    assert result["slow_periods"] == 0  # both clients answered every measurement
    for key in ("real_time_factor", "world_only_real_time_factor", "ratio", "cpu_ratio"):
        value = result[key]
        assert isinstance(value, float) and value > 0, key
    assert result["round_trip_p50_ms"] is not None
    cost = result["neighbour_cost"]  # the step beside a busy clients' CPU, timed before the run
    if len(os.sched_getaffinity(0)) >= 2:
        assert isinstance(cost, dict) and cost["idle_us"] > 0 and cost["busy_us"] > 0, cost
        assert cost["ratio"] == pytest.approx(cost["busy_us"] / cost["idle_us"], rel=0.01)
    else:
        assert cost is None  # the clients share the step thread's CPU: nothing to keep busy


@pytest.mark.slow
def test_bench_api_camera_and_stalled_client() -> None:
    result = _bench(
        "--mode", "async", "--camera", "320x240@32", "--sim-seconds", "0.25", "--stalled-client"
    )
    assert result["camera_robots"] == 2
    assert result["neighbour_cost"] is None  # with cameras every CPU is shared: none to keep busy
    assert isinstance(result["camera_frames"], int) and result["camera_frames"] >= 8
    bare, ours = result["bare_render_ms_per_frame"], result["camera_path_ms_per_frame"]
    assert isinstance(bare, float) and isinstance(ours, float) and bare > 0 and ours > 0
    assert result["render_cost_ratio"] == pytest.approx(ours / bare, abs=0.01)
    stalled = result["stalled_client"]
    assert isinstance(stalled, dict) and stalled["real_time_factor"] > 0
    assert stalled["cpu_ratio"] > 0


def test_bench_api_league_clients_report_their_rate_and_both_round_trips() -> None:
    result = _bench("--mode", "lockstep", "--client", "league", "--sim-seconds", "0.5")
    assert result["client"] == "league"
    league = result["league_client"]
    assert isinstance(league, dict)
    assert league["clients"] == 2 and league["reported"] == 2
    # one request per robot and step: requests per second of the API run are its steps'
    steps_per_s = float(result["real_time_factor"]) * 1000.0 / 8
    assert league["requests_per_s"] == pytest.approx(2 * steps_per_s, rel=0.1)
    for key in ("round_trip_p50_ms", "client_answer_p50_ms", "client_round_trip_p50_ms",
                "server_reply_p50_ms"):
        assert isinstance(league[key], float) and league[key] > 0, key
    # the server's view of the client's wait against the client's own (the transits apart)
    assert league["server_over_client"] == round(
        league["server_reply_p50_ms"] / league["client_round_trip_p50_ms"], 3)
    assert result["slow_periods"] == 0
    # judged as the report judges lockstep: the run's ratio to the world alone
    assert league["ratio_interleaved"] == result["ratio_interleaved"]
    assert league["target"] == {"figure": "ratio_interleaved", "min": 0.85}
    ratio = result["ratio_interleaved"]
    assert isinstance(ratio, float) and league["meets_target"] == (ratio >= 0.85)


def test_bench_api_flood_reports_the_honest_robots_with_and_without_it() -> None:
    result = _bench("--mode", "lockstep", "--sim-seconds", "0.5", "--flood")
    flood = result["flood"]
    assert isinstance(flood, dict) and flood["honest_robots"] == 1
    assert flood["flooder_slow_periods"] >= 1 and flood["honest_slow_periods"] == 0
    assert flood["flooder_messages_in"] > 0
    for key in ("real_time_factor", "real_time_factor_without", "ratio", "ratio_interleaved",
                "round_trip_p50_ms", "round_trip_p50_ms_without", "round_trip_ratio"):
        assert isinstance(flood[key], float) and flood[key] > 0, key
    assert flood["ratio"] == pytest.approx(
        flood["real_time_factor"] / flood["real_time_factor_without"], abs=0.01
    )
    # the honest robots' pace with the flood over without: at least 0.8 meets the target
    assert flood["target"] == {"figure": "ratio_interleaved", "min": 0.8}
    assert flood["meets_target"] == (flood["ratio_interleaved"] >= 0.8)


def test_bench_api_clients_in_one_process_answer_every_robot() -> None:
    result = _bench("--mode", "lockstep", "--client", "one-process", "--sim-seconds", "0.5")
    assert result["client"] == "one-process"
    assert result["slow_periods"] == 0  # both robots' answers came, every step
    assert result["round_trip_p50_ms"] is not None
    interleaved = result["ratio_interleaved"]
    assert isinstance(interleaved, float) and interleaved > 0


def test_bench_api_native_clients_and_the_lockstep_floor() -> None:
    result = _bench("--mode", "lockstep", "--native", "--sim-seconds", "0.5")
    assert result["native_clients"] is True and result["client"] == "bench"
    assert result["slow_periods"] == 0 and result["dropped_in"] == 0  # every step answered
    assert result["round_trip_p50_ms"] is not None
    floor = result["lockstep_floor"]
    assert isinstance(floor, dict), floor
    assert floor["clients"] == 2 and floor["steps"] > 0
    assert 0 < floor["ratio"] <= 1
    assert floor["measurement_bytes"] > 100  # the API run's measurements, not a token size
    assert floor["of_floor"] == pytest.approx(result["ratio_interleaved"] / floor["ratio"],
                                              abs=0.01)  # fmt: skip


def test_bench_api_native_league_clients_meet_no_delayed_ack_stall() -> None:
    """Compiled clients written like the league's (length and body in two writes, no
    TCP_NODELAY) against the API server and against the floor: a 40 ms delayed-ACK stall a
    step would put either far below these figures."""
    result = _bench("--mode", "lockstep", "--client", "league", "--native", "--sim-seconds", "0.5")
    league = result["league_client"]
    assert isinstance(league, dict) and league["clients"] == 2 and league["reported"] == 2
    for key in ("client_answer_p50_ms", "client_round_trip_p50_ms", "server_reply_p50_ms"):
        assert isinstance(league[key], float) and 0 < league[key] < 20, key
    steps_per_s = float(result["real_time_factor"]) * 1000.0 / 8  # type: ignore[arg-type]
    assert league["requests_per_s"] == pytest.approx(2 * steps_per_s, rel=0.15)
    assert league["round_trip_p50_ms"] < 20
    floor = result["lockstep_floor"]
    assert isinstance(floor, dict) and floor["wait_us_per_step"] < 20_000, floor


def test_bench_api_native_refuses_the_one_process_client() -> None:
    proc = subprocess.run(
        [sys.executable, "-m", "benchmarks", "api", "--client", "one-process", "--native",
         "--json"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode != 0
    assert "--native: runs --client bench or league, not one-process" in proc.stderr
