from __future__ import annotations

import logging

import pytest

from orchestrator.match import IllegalMatchTransition, Lifecycle, MatchState


class Clock:
    def __init__(self) -> None:
        self.now = 0.0

    def __call__(self) -> float:
        return self.now


def test_full_lifecycle_records_time_per_state_and_logs(caplog: pytest.LogCaptureFixture) -> None:
    clock = Clock()
    life = Lifecycle("m1", clock=clock)
    caplog.set_level(logging.INFO, logger="orchestrator.match.state")
    for step, state in enumerate([MatchState.PULLING, MatchState.STARTING, MatchState.WAITING,
                                  MatchState.PLAYING, MatchState.STOPPING, MatchState.COLLECTING,
                                  MatchState.DONE], start=1):
        clock.now = float(step)
        life.advance(state)
    assert life.state is MatchState.DONE
    assert life.timings_s["pending"] == 1.0 and life.timings_s["collecting"] == 1.0
    assert len([r for r in caplog.records if "->" in r.getMessage()]) == 7
    assert "match m1: COLLECTING -> DONE" in caplog.records[-1].getMessage()


@pytest.mark.parametrize(
    ("path", "target"),
    [
        ([], MatchState.PLAYING),
        ([MatchState.PULLING], MatchState.DONE),
        ([MatchState.PULLING, MatchState.STARTING], MatchState.COLLECTING),
        ([MatchState.FAILED], MatchState.PULLING),
        ([MatchState.PULLING, MatchState.STOPPING, MatchState.COLLECTING, MatchState.DONE],
         MatchState.FAILED),
    ],
)
def test_illegal_transitions_are_rejected(path: list[MatchState], target: MatchState) -> None:
    life = Lifecycle("m2")
    for state in path:
        life.advance(state)
    before = life.state
    with pytest.raises(IllegalMatchTransition) as info:
        life.advance(target)
    assert info.value.source is before and info.value.target is target
    assert "m2" in str(info.value) and "allowed from" in str(info.value)
    assert life.state is before


def test_safe_names_and_bandwidth_keys() -> None:
    from orchestrator.bandwidth import _ip_key, _udp_port_key, mb_s_to_bit
    from orchestrator.match.logfs import safe_name

    assert safe_name("round-1.a_b") == "round-1.a_b"  # a valid match id is itself
    assert safe_name("round 1/a:b").startswith("_round-1-a-b-")
    assert safe_name("../x").startswith("_..-x-")
    # ids that differ only in punctuation or spaces never share a name
    names = {safe_name(text) for text in ("Bit Bots", "Bit-Bots", "Bit_Bots", "Bit/Bots",
                                          "Bit:Bots", "_Bit-Bots", "bit bots")}
    assert len(names) == 7
    assert all(len(n) <= 100 and "/" not in n for n in names)
    assert mb_s_to_bit(350 / 4) == 700_000_000
    assert mb_s_to_bit(1.0) == 8_000_000
    assert _ip_key("10.213.4.12", 16) == "0x0ad5040c/0xffffffff+16"
    assert _udp_port_key(3737, source=False) == "0x00000e99/0x0000ffff+20"
    assert _udp_port_key(3737, source=True) == "0x0e990000/0xffff0000+20"
