"""What a busy CPU beside the step thread costs the step: the ``neighbour_cost`` figure of
``bench api``.

On a virtual machine two virtual CPUs can be two threads of one physical core, at some times and
not at others: then whatever runs on the clients' CPU slows the step thread's own computation,
which the step thread's CPU time shows (a thread sharing a core runs slower, it is not
descheduled: the hypervisor's ``steal`` does not count it). Pipelined stepping computes the
world while its I/O thread and the clients run on the other CPU, so a run in such a stretch of
time is slower though nothing of ours changed; lockstep, whose clients answer while the step
thread waits, much less so.

:func:`cost` times chunks of a step (a reference world's, on the calling thread) with the
given CPU idle and with a process spinning on it, alternated, and gives their CPU time a step
and the ratio: about 1 where the two CPUs do not share a core, a quarter or more above it where
they do.
"""

from __future__ import annotations

import multiprocessing as mp
import os
import time
from collections.abc import Callable
from typing import Any

from testkit.figures import process_cpu_s

ROUNDS = 10  # alternations of an idle and a busy chunk
CHUNK_STEPS = 25  # steps a chunk
SETTLE_S = 0.005  # after the spinner is switched, before the chunk is timed
# a ratio from which the two CPUs are taken to share a core: on our 2-CPU virtual machine the
# ratio was 0.98-1.08 in most runs and 1.17-1.45 in the stretches of seconds when a pipelined
# run was a quarter slower (README, performance)
SHARED_CORE_RATIO = 1.15


def shared_core_runs(ratios: list[float | None]) -> int:
    """How many of the runs' neighbour ratios say that the two CPUs shared a core."""
    return sum(1 for r in ratios if r is not None and r >= SHARED_CORE_RATIO)


def shared_core_note(ratio: float | None) -> str | None:
    """What to tell the reader of a run timed while the two CPUs shared a core; None else."""
    if ratio is None or ratio < SHARED_CORE_RATIO:
        return None
    return (f"timed while the step thread's CPU shared a physical core with the clients' "
            f"(neighbour ratio {ratio:.2f}): the host's placement slows this run, not our code")


def _spin(cpu: int, busy: Any) -> None:
    """Spinner process: while ``busy`` is set, an integer loop on ``cpu``; else it sleeps."""
    os.sched_setaffinity(0, {cpu})
    while True:
        if busy.value:
            total = 0
            for i in range(20_000):
                total += i
        else:
            time.sleep(0.0005)


def cost(step: Callable[[], None], cpu: int, rounds: int = ROUNDS,
         chunk: int = CHUNK_STEPS) -> dict[str, float | None]:
    """``step``'s CPU microseconds a call with ``cpu`` idle and with it busy (``idle_us``,
    ``busy_us``) and their ratio (``ratio``: busy over idle; None when the idle chunks took no
    measurable time), from ``rounds`` alternations of ``chunk`` calls each, and the spinner's
    CPU time over the wall time it was to be busy (``spinner_share``: about 1 when it had its CPU;
    None where ``/proc`` cannot tell). The caller's thread should not be allowed to run on
    ``cpu``."""
    if rounds < 1 or chunk < 1:
        raise ValueError(f"rounds and chunk: at least 1 each, not {rounds} and {chunk}")
    ctx = mp.get_context("fork")
    busy = ctx.Value("b", 0, lock=False)
    spinner = ctx.Process(target=_spin, args=(cpu, busy), daemon=True)
    spinner.start()
    spent = {0: 0.0, 1: 0.0}
    busy_wall = 0.0
    try:
        spinner_before = process_cpu_s(spinner.pid)
        for _ in range(rounds):
            for state in (0, 1):
                switched = time.perf_counter()
                busy.value = state
                time.sleep(SETTLE_S)
                started = time.thread_time()
                for _ in range(chunk):
                    step()
                spent[state] += time.thread_time() - started
                busy_wall += (time.perf_counter() - switched) if state else 0.0
        spinner_after = process_cpu_s(spinner.pid)
    finally:
        spinner.kill()
        spinner.join(timeout=5)
    calls = rounds * chunk
    idle_us, busy_us = (spent[state] / calls * 1e6 for state in (0, 1))
    return {
        "idle_us": round(idle_us, 1),
        "busy_us": round(busy_us, 1),
        "ratio": round(spent[1] / spent[0], 3) if spent[0] > 0 else None,
        "spinner_share": round((spinner_after - spinner_before) / busy_wall, 3)
        if spinner_before is not None and spinner_after is not None and busy_wall > 0
        else None,
    }

