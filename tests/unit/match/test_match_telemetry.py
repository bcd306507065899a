"""ZenohTelemetry against a real zenoh publisher on loopback; the plain progress view."""

from __future__ import annotations

import io
import json
import time
from dataclasses import replace

import zenoh

from contracts.telemetry import StateMessage
from orchestrator.telemetry import LiveView, ZenohTelemetry, describe
from testkit.sftp import free_port


def test_subscriber_receives_state_and_events_from_a_listening_publisher() -> None:
    endpoint = f"tcp/127.0.0.1:{free_port()}"
    watcher = ZenohTelemetry(endpoint=endpoint, match_id="tm1")  # before the publisher exists
    config = zenoh.Config()
    config.insert_json5("mode", '"peer"')
    config.insert_json5("scouting/multicast/enabled", "false")
    config.insert_json5("listen/endpoints", json.dumps([endpoint]))
    publisher = zenoh.open(config)
    try:
        state = {"state": "READY", "half": 1, "score": {"red": 0, "blue": 0},
                 "connected": ["red-1"], "sim_time_ms": 1200, "real_time_factor": 1.0,
                 "secondary_state": "NORMAL", "secs_remaining": 40, "stepping": "async",
                 "robots": None}
        deadline = time.monotonic() + 20
        while watcher.latest() is None and time.monotonic() < deadline:
            publisher.put("hlvs/tm1/state", json.dumps(state))
            publisher.put("hlvs/other/state", json.dumps({"state": "PLAYING"}))
            publisher.put("hlvs/tm1/events", json.dumps({"type": "GOAL"}))
            time.sleep(0.1)
        assert watcher.latest() == StateMessage.from_dict(state, source="test")
        assert watcher.last_message_at() is not None
        deadline = time.monotonic() + 5
        while not watcher.events() and time.monotonic() < deadline:
            time.sleep(0.05)
        assert watcher.events()[0] == {"type": "GOAL"}
        # the first message of a new state is read once before newer ones (the console line
        # at the first PLAYING shows the full half however fast the match runs)
        for secs in (60, 59, 58):
            publisher.put("hlvs/tm1/state", json.dumps({**state, "state": "PLAYING",
                                                        "secs_remaining": secs}))
        deadline = time.monotonic() + 5
        while (latest := watcher.latest()) is None or latest.secs_remaining != 58:
            assert time.monotonic() < deadline
            time.sleep(0.05)
        publisher.put("hlvs/tm1/state", json.dumps({**state, "state": "SET", "half": 2,
                                                    "secs_remaining": 60}))
        publisher.put("hlvs/tm1/state", json.dumps({**state, "state": "SET", "half": 2,
                                                    "secs_remaining": 50}))
        deadline = time.monotonic() + 5
        seen: list[tuple[str | None, float | None]] = []
        while (not seen or seen[-1][1] != 50) and time.monotonic() < deadline:
            message = watcher.latest()
            assert message is not None
            if message.half == 2:
                seen.append((message.state, message.secs_remaining))
            time.sleep(0.05)
        assert seen[0] == ("SET", 60) and seen[-1] == ("SET", 50), seen
    finally:
        watcher.close()
        publisher.close()


def _message(**fields: object) -> StateMessage:
    data: dict[str, object] = {
        "sim_time_ms": 0, "real_time_factor": 0.0, "state": None, "secondary_state": None,
        "half": None, "secs_remaining": None, "score": None, "connected": [],
        "stepping": "async", "robots": None}
    return StateMessage.from_dict({**data, **fields}, source="test")


def test_plain_view_prints_changes_only() -> None:
    out = io.StringIO()
    view = LiveView(match_id="m", stream=out)
    state = _message(state="PLAYING", half=1, score={"red": 1, "blue": 0}, connected=[])
    view.update(phase="playing", state=state)
    view.update(phase="playing", state=replace(state, sim_time_ms=500))
    view.update(phase="playing", state=replace(state, score={"red": 2, "blue": 0}))
    lines = out.getvalue().splitlines()
    assert len(lines) == 2
    assert "score red 2 - 0 blue" in lines[1]
    assert describe(state).startswith("PLAYING half 1")


class _Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


def test_terminal_view_renders_a_table() -> None:
    out = _Terminal()
    view = LiveView(match_id="m9", stream=out)
    view.update(phase="playing", state=_message(
        state="SET", secondary_state="NORMAL", half=2, secs_remaining=12,
        score={"red": 3, "blue": 1}, sim_time_ms=4500, real_time_factor=1.5,
        connected=["red-1", "blue-1"]))
    view.close()
    text = out.getvalue()
    assert "match m9" in text and "red 3 - 1 blue" in text and "red-1, blue-1" in text


def test_the_progress_line_shows_the_seconds_left_with_one_decimal() -> None:
    state = _message(state="PLAYING", half=2, secs_remaining=60, score={"red": 0, "blue": 0})
    assert describe(state).startswith("PLAYING half 2 60.0 s left")
    assert " ? s left" in describe(replace(state, secs_remaining=None))


def test_subscribers_retry_the_simulator_often_while_it_starts() -> None:
    """The orchestrator's and the live viewer's subscriber start while the simulator boots:
    retried every 0.1 s at first and never more than 0.5 s apart (zenoh's 1, 2, 4 s made
    the bring-up up to 3 s longer), to the one endpoint, without scouting."""
    from orchestrator.telemetry import subscriber_config

    config = subscriber_config("tcp/10.0.0.2:7447")
    retry = json.loads(config.get_json("connect/retry"))
    assert retry["period_init_ms"] == 100 and retry["period_max_ms"] == 500
    assert json.loads(config.get_json("connect/endpoints")) == ["tcp/10.0.0.2:7447"]
    assert json.loads(config.get_json("scouting/multicast/enabled")) is False
