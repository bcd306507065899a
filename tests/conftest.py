"""Shared test settings. Integration tests mark what they need (docker, root), clean up by label.

``make test`` runs the suite on two pytest-xdist workers (``--dist loadgroup``), by groups
(:func:`worker_group`). Each folder of ``tests/integration`` (and each file directly in it) is
one group, run by one worker from start to end: its tests were written to run one after
another. A test that uses a fixture of which the machine has one (the Slurm cluster) joins the
group of that fixture's folder (:data:`ONE_OF_A_KIND`). Two groups, or a group and the
in-process tests, may run at once: they share only the Docker engine, where every match has its
own id, networks and containers, and PostgreSQL, where every test has its own database. Most
integration tests wait on matches played in real time, so the second worker uses CPU the first
leaves idle. Every other test module is a group of its own (its module fixtures are built once).
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Iterator
from pathlib import Path, PurePosixPath
from typing import Any

import pytest

# Offscreen rendering without a display (MuJoCo reads this at import time).
os.environ.setdefault("MUJOCO_GL", "osmesa")
os.environ.setdefault("PYOPENGL_PLATFORM", "osmesa")

TEST_LABEL = "org.hlvs-runner.test"

# Test files outside a one-of-a-kind fixture's folder that use it, and that folder's group: the
# Slurm cluster (its daemons, nodes and accounting) of tests/integration/pool/conftest.py. The
# scheduler sees test ids only, so files are named here (tests/unit/test_worker_groups.py checks
# that every user of the fixture is).
ONE_OF_A_KIND = {
    "integration/viewer/test_viewer_pool_nodes.py": "integration/pool",
}


def worker_group(nodeid: str) -> str:
    """The group of a test id (``tests/...py::name``): that of a one-of-a-kind fixture its file
    uses, else its integration folder, else its file."""
    path = PurePosixPath(nodeid.split("::", 1)[0])
    parts = path.parts[1:] if path.parts and path.parts[0] == "tests" else path.parts
    relative = "/".join(parts)
    if relative in ONE_OF_A_KIND:
        return ONE_OF_A_KIND[relative]
    if len(parts) > 2 and parts[0] == "integration":
        return "/".join(parts[:2])
    return relative


# The longest groups (their tests' wall time in a full run, 2026-12-02: the README commands 682 s,
# the service 549 s, the Slurm pool 462 s, the matches 420 s, the attacks' matches, under two
# runtimes, about 400 s), handed out first: the many short groups then fill the other worker's
# time, instead of a long group started late leaving it idle at the end (longest first).
LONG_GROUPS_FIRST = (
    "integration/test_readme_commands.py",
    "integration/service",
    "integration/pool",
    "integration/match",
    "integration/attack",
)


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """``--dist loadgroup``: the groups of :data:`LONG_GROUPS_FIRST` first, in that order, the
    rest as collected (every worker collects, and sorts, alike)."""
    if config.getvalue("dist") != "loadgroup":
        return
    rank = {group: k for k, group in enumerate(LONG_GROUPS_FIRST)}
    items.sort(key=lambda item: rank.get(worker_group(item.nodeid), len(rank)))


def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    """``--dist loadgroup``: whole groups of :func:`worker_group` to a worker at a time, in the
    order collected (with ``--no-loadscope-reorder``; :func:`pytest_collection_modifyitems`
    puts the longest first)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadScopeScheduling

    class GroupScheduling(LoadScopeScheduling):
        def _split_scope(self, nodeid: str) -> str:
            return worker_group(nodeid)

    return GroupScheduling(config, log)


# A deadline for the whole run (seconds since the epoch, set by .ci/run): past it no test starts,
# and a test that starts before it gets at most the time left, so a run that cannot finish in
# time (a slow machine, a hung engine) still ends with its report: what passed, what failed and
# why, and how many tests it left.
DEADLINE_ENV = "HLVS_TEST_DEADLINE"
DEADLINE = pytest.StashKey[float | None]()


def _deadline() -> float | None:
    value = os.environ.get(DEADLINE_ENV, "").strip()
    try:
        return float(value) if value else None
    except ValueError:
        message = f"{DEADLINE_ENV}={value!r}: expected seconds since the epoch"
        raise pytest.UsageError(message) from None


@pytest.hookimpl(wrapper=True, tryfirst=True)
def pytest_runtest_protocol(item: pytest.Item, nextitem: pytest.Item | None) -> Iterator[None]:
    """Outside pytest-timeout's own wrapper, which sets the test's timer."""
    deadline = item.config.stash.get(DEADLINE, None)
    left = None if deadline is None else deadline - time.time()
    if left is not None and left <= 0:
        item.session.shouldstop = f"{DEADLINE_ENV} passed: no further test started"
        item.add_marker(pytest.mark.skip(reason=f"{DEADLINE_ENV} passed before it started"))
    elif left is not None:
        marker = item.get_closest_marker("timeout")
        own = item.config.getini("timeout")
        if marker is not None:
            own = marker.args[0] if marker.args else marker.kwargs.get("timeout", own)
        if not own or float(own) > left:
            # Rounded up: a timer that fires before the deadline would let the next test start.
            item.add_marker(pytest.mark.timeout(math.ceil(left)), append=False)
    return (yield)


MACHINE_AT_START = pytest.StashKey[str]()


def pytest_configure(config: pytest.Config) -> None:
    """The deadline, read once (a value that is not a time stops the run before it starts);
    the machine's speed, measured once by the controller of an xdist run or a plain run."""
    config.stash[DEADLINE] = _deadline()
    if not hasattr(config, "workerinput"):
        config.stash[MACHINE_AT_START] = _machine_speed()


GROUP_SECONDS: dict[str, list[float]] = {}  # worker group: [seconds of its tests, tests]


def pytest_runtest_logreport(report: pytest.TestReport) -> None:
    """Each test's set-up, call and teardown time, added to its worker group's (on the
    controller, which hears every worker's reports)."""
    entry = GROUP_SECONDS.setdefault(worker_group(report.nodeid), [0.0, 0])
    entry[0] += report.duration
    if report.when == "call":
        entry[1] += 1


def _slowest_groups(count: int = 8) -> str:
    """The groups that took longest, on one line: a group runs on one worker from start to end,
    so the longest bounds the run's wall time."""
    ranked = sorted(GROUP_SECONDS.items(), key=lambda item: -item[1][0])[:count]
    return ", ".join(f"{group} {seconds:.0f} s ({int(tests)} tests)"
                     for group, (seconds, tests) in ranked)


def pytest_terminal_summary(terminalreporter: Any, config: pytest.Config) -> None:
    """The machine's speed at the start and at the end, near the end of the report (what a CI
    log keeps), for a reader who compares a slow run with a good one; the slowest worker groups."""
    if GROUP_SECONDS:
        terminalreporter.write_line(f"slowest test groups: {_slowest_groups()}")
    if MACHINE_AT_START in config.stash:
        setup = _setup_times()
        if setup:
            terminalreporter.write_line(f"set-up before the tests: {setup}")
        terminalreporter.write_line(f"machine at the start: {config.stash[MACHINE_AT_START]}")
        terminalreporter.write_line(f"machine at the end: {_machine_speed()}")


SETUP_TIMES_ENV = "HLVS_SETUP_TIMES"  # a file of "<step> <seconds> s" lines (.ci/run)


def _setup_times() -> str:
    """The set-up steps' times from :data:`SETUP_TIMES_ENV`, on one line ("" without it)."""
    name = os.environ.get(SETUP_TIMES_ENV, "")
    try:
        lines = Path(name).read_text(encoding="utf-8").splitlines() if name else []
    except OSError:
        return ""
    return ", ".join(line.strip() for line in lines if line.strip())


def _machine_speed() -> str:
    """A fixed Python loop's time, and the CPU time the hypervisor took meanwhile (``steal`` in
    /proc/stat)."""
    steal_before = _cpu_times()
    wall, cpu = time.perf_counter(), time.process_time()
    total = 0
    for i in range(2_000_000):
        total += i
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    steal_after = _cpu_times()
    stolen = ""
    if steal_before and steal_after and len(steal_after) > 7:
        spent = sum(steal_after[:8]) - sum(steal_before[:8])
        share = (steal_after[7] - steal_before[7]) / spent if spent > 0 else 0.0
        stolen = f", {share:.0%} of the CPUs' time stolen meanwhile"
    load = ", ".join(f"{value:.1f}" for value in os.getloadavg())
    return (f"{os.cpu_count()} CPUs, load average {load}; a 2e6-step Python loop took "
            f"{wall:.2f} s ({cpu:.2f} s of CPU){stolen}")


def _cpu_times() -> list[int] | None:
    """The machine's CPU times (user, nice, system, idle, iowait, irq, softirq, steal, ...)."""
    try:
        fields = Path("/proc/stat").read_text().split("\n", 1)[0].split()[1:]
        return [int(field) for field in fields]
    except (OSError, ValueError):
        return None
