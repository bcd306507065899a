"""``testkit.neighbour``: a step timed with the clients' CPU idle and busy, alternated."""

from __future__ import annotations

import multiprocessing as mp
import os
import time

import pytest

from testkit import figures, neighbour


def _work() -> None:
    total = 0
    for i in range(2_000):
        total += i * i


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs a second CPU to keep busy")
def test_the_step_is_timed_idle_and_busy_and_the_spinner_ends() -> None:
    cpus = sorted(os.sched_getaffinity(0))
    before = set(mp.active_children())
    os.sched_setaffinity(0, {cpus[0]})
    try:
        result = neighbour.cost(_work, cpus[1], rounds=4, chunk=2000)  # 0.1 s a chunk or more
    finally:
        os.sched_setaffinity(0, set(cpus))
    idle, busy, ratio = result["idle_us"], result["busy_us"], result["ratio"]
    assert idle is not None and busy is not None and ratio is not None
    assert idle > 0 and busy > 0
    assert ratio == pytest.approx(busy / idle, rel=0.01)
    # the spinner ran while the busy chunks were timed: about 1 on a quiet machine, less where
    # other processes share its CPU (the suite's other worker); a spinner that only slept, as
    # in the idle chunks, would be at a few hundredths
    share = result["spinner_share"]
    assert share is not None and 0.15 < share < 1.6, share
    assert set(mp.active_children()) == before  # the spinner is gone


def test_rounds_and_chunks_must_be_positive() -> None:
    with pytest.raises(ValueError, match="at least 1"):
        neighbour.cost(_work, 0, rounds=0)


def test_runs_from_the_shared_core_ratio_up_are_counted() -> None:
    assert neighbour.shared_core_runs([0.99, None, 1.15, 1.44, 1.149]) == 2
    assert neighbour.shared_core_runs([]) == 0


def test_a_run_on_a_shared_core_is_told_and_others_are_not() -> None:
    note = neighbour.shared_core_note(1.438)
    assert note is not None and "shared a physical core" in note and "1.44" in note
    assert neighbour.shared_core_note(1.149) is None and neighbour.shared_core_note(None) is None


def test_a_process_cpu_time_is_read_and_a_gone_process_has_none() -> None:
    before = figures.process_cpu_s(os.getpid())
    assert before is not None
    _work_for(0.05)
    after = figures.process_cpu_s(os.getpid())
    assert after is not None and after >= before + 0.02  # clock ticks of 10 ms
    child = mp.get_context("fork").Process(target=_work)
    child.start()
    child.join()
    assert figures.process_cpu_s(child.pid) is None  # reaped: no /proc entry


def _work_for(seconds: float) -> None:
    end = time.thread_time() + seconds
    while time.thread_time() < end:
        _work()
