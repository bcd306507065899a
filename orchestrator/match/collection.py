"""STOPPING and COLLECTING: grace period, logs, public files, teardown, results, report.

Every teardown step runs even when an earlier one failed; a teardown failure makes the match an
``infrastructure`` failure only when nothing else failed first. ``report.json`` is written last.
"""

from __future__ import annotations

import importlib.metadata
import logging
import shutil
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import replace
from functools import partial
from pathlib import Path

from contracts import (
    ContractError,
    MatchLimits,
    MatchResults,
    MatchSpec,
    SimResult,
    TimingSpec,
    files,
)
from orchestrator.errors import OrchestratorError
from orchestrator.match import layout
from orchestrator.match.context import MatchContext
from orchestrator.match.logfs import LogFolder
from orchestrator.match.results import (
    FailureClass,
    build_results,
    play_failure,
    write_report,
    write_results,
)
from orchestrator.match.safecopy import restrict
from orchestrator.match.state import MatchState

log = logging.getLogger(__name__)

PUBLIC_FILES = files.PUBLIC_FILES


def read_sim_result(match: MatchContext) -> SimResult | None:
    """The simulator's ``sim_result.json``; None when it is missing or does not fit the contract
    (logged with the file, field and reason)."""
    match_dir = match.started.match_dir
    if match_dir is None:
        return None
    path = match_dir / files.OUT_DIR / files.SIM_RESULT
    if not path.exists():
        return None
    try:
        return SimResult.load(path)
    except ContractError as exc:
        log.error("match %s: %s", match.plan.match_id, exc)
        return None


def simulator_stderr_tail(match: MatchContext) -> str:
    sim_id = match.started.simulator_id
    match_dir = match.started.match_dir
    if sim_id is None or match_dir is None:
        return ""
    try:
        match.runtime.save_logs(sim_id, stdout=match_dir / "stdout.log",
                                 stderr=match_dir / "stderr.log")
        lines = (match_dir / "stderr.log").read_text(errors="replace").strip().splitlines()
    except (OrchestratorError, OSError):
        return ""
    return lines[-1][:300] if lines else ""


def _guarded(match: MatchContext, what: str, step: Callable[[], object]) -> None:
    """Run one step of stopping, collecting or teardown; a failure fails the match (the first
    one counts) and the next steps still run."""
    try:
        step()
    except (OrchestratorError, OSError) as exc:
        log.error("match %s: %s failed: %s", match.plan.match_id, what, exc)
        match.fail(FailureClass.INFRASTRUCTURE, f"{what}: {exc}")
    except Exception as exc:  # noqa: BLE001 - the steps after this one must still run
        log.exception("match %s: %s failed", match.plan.match_id, what)
        match.fail(FailureClass.INFRASTRUCTURE, f"{what}: {type(exc).__name__}: {exc}")


def _stop_robots(match: MatchContext) -> None:
    grace = match.plan.grace_period_s
    ids = match.started.robot_ids

    def stop(item: tuple[str, str]) -> None:
        key, container_id = item
        _guarded(match, f"stopping robot {key}",
                 lambda: match.runtime.stop(container_id, timeout_s=grace))

    if ids:
        log.info("match %s: stopping %d robots (grace %.0f s)", match.plan.match_id, len(ids),
                 grace)
        with ThreadPoolExecutor(max_workers=min(8, len(ids))) as pool:
            list(pool.map(stop, ids.items()))


def _read_counters(match: MatchContext) -> None:
    for key, applied in match.started.shaping.items():
        record = match.records[key]
        try:
            counters = match.host.counters(applied)
        except OrchestratorError as exc:
            log.warning("match %s: no traffic counters for %s: %s", match.plan.match_id, key, exc)
            continue
        record.sent_bytes = counters.sent_bytes
        record.received_bytes = counters.received_bytes


def _team_guarded(match: MatchContext, key: str, what: str, step: Callable[[], object]) -> None:
    """A step that touches what a robot made: an engine failure fails the match (as
    :func:`_guarded`), anything else costs only this robot's logs, named in report.json."""
    try:
        step()
    except (OrchestratorError, OSError) as exc:
        log.error("match %s: %s failed: %s", match.plan.match_id, what, exc)
        match.fail(FailureClass.INFRASTRUCTURE, f"{what}: {exc}")
    except Exception as exc:  # noqa: BLE001 - a robot's output never breaks the match record
        log.exception("match %s: %s failed", match.plan.match_id, what)
        match.logs_cut.append({"robot": key, "what": what,
                               "reason": f"{type(exc).__name__}: {exc}"})


def _collect_robot(match: MatchContext, key: str, container_id: str) -> None:
    record = match.records[key]
    folder = match.options.out_dir / "teams" / record.color / str(record.number)
    state = match.runtime.inspect(container_id)
    record.exit_code = state.exit_code
    record.oom_killed = record.oom_killed or state.oom_killed
    record.restarts = state.restart_count
    peaks = match.monitor.peaks(key)
    record.cpu_peak_percent = peaks.cpu_percent
    record.memory_peak_bytes = peaks.memory_bytes
    cap = layout.ROBOT_CONSOLE_BYTES // 2  # per stream (the engine keeps less of a flood)
    cut = match.runtime.save_logs(container_id, stdout=folder / "stdout.log",
                                   stderr=folder / "stderr.log", max_bytes=cap)
    for stream in cut:
        match.logs_cut.append({"robot": key, "what": f"{stream}.log",
                               "reason": f"cut at the limit of {cap} bytes"})


def _copy_public(match: MatchContext) -> None:
    match_dir = match.started.match_dir
    public = match.options.out_dir / "public"
    public.mkdir(parents=True, exist_ok=True)
    if match_dir is None:
        return
    for name in PUBLIC_FILES:
        source = match_dir / files.OUT_DIR / name
        if source.is_file():
            shutil.copy2(source, public / name)


def _collect_log_folder(match: MatchContext, key: str, folder: LogFolder,
                        destination: Path) -> None:
    """What a team wrote never fails the match: only releasing the mount can raise."""
    limit = int(match.plan.limits.log_folder_gb * 1e9)
    report = match.host.collect_logs(folder, destination, limit_bytes=limit)
    match.records[key].log_folder = report.record()
    if report.stopped:
        match.logs_cut.append({"robot": key, "what": "robocup-logs", "reason": report.stopped})
    if report.skipped_count:
        log.warning("match %s: %s: %d entries of /robocup-logs not collected (%s)",
                    match.plan.match_id, key, report.skipped_count,
                    ", ".join(f"{s['path']}: {s['kind']}" for s in report.skipped[:5]))


def _teardown(match: MatchContext) -> None:
    started = match.started
    runtime = match.runtime
    for key, container_id in list(started.robot_ids.items()) + list(started.holder_ids.items()):
        _guarded(match, f"removing container of {key}", partial(runtime.remove, container_id))
    if started.simulator_id is not None:
        sim_id = started.simulator_id
        _guarded(match, "removing the simulator", lambda: runtime.remove(sim_id))
    for key, folder in started.log_folders.items():
        record = match.records[key]
        target = match.options.out_dir / "teams" / record.color / str(record.number)
        _team_guarded(match, key, f"releasing /robocup-logs of {key}",
                      partial(_collect_log_folder, match, key, folder, target / "robocup-logs"))
    for key, scratch in started.scratch.items():
        _guarded(match, f"releasing the scratch space of {key}",
                 partial(match.host.release, scratch))
    for applied in started.node_shaping:  # league placement: the nodes outlive the match
        _guarded(match, f"removing the bandwidth limits of {applied.netns}",
                 partial(match.host.unshape, applied))
    for netns in started.node_firewalls:
        _guarded(match, f"removing the robot node firewall of {netns}",
                 partial(match.host.remove_node_firewall, netns))
    for network in started.networks.values():
        _guarded(match, f"removing network {network.name}",
                 partial(runtime.remove_network, network.name))
    _guarded(match, "removing host firewall rules",
             lambda: match.host.remove_isolation(match_id=match.plan.match_id))


def _finish(match: MatchContext) -> MatchResults:
    """Run STOPPING and COLLECTING from wherever the match got to; returns the results. The
    teardown and the match record (results.json, report.json) happen whatever breaks before."""
    try:
        _stop_and_collect(match)
    except Exception as exc:  # noqa: BLE001 - the record is written and everything removed
        log.exception("match %s: collection failed", match.plan.match_id)
        match.fail(FailureClass.INFRASTRUCTURE, f"collection failed: {type(exc).__name__}: {exc}")
    try:
        _teardown(match)
    except Exception as exc:  # noqa: BLE001
        log.exception("match %s: teardown failed", match.plan.match_id)
        match.fail(FailureClass.INFRASTRUCTURE, f"teardown failed: {type(exc).__name__}: {exc}")
    return _write(match)


def _stop_and_collect(match: MatchContext) -> None:
    lifecycle = match.lifecycle
    if lifecycle.state in (MatchState.PULLING, MatchState.STARTING, MatchState.WAITING,
                           MatchState.PLAYING):
        match.advance(MatchState.STOPPING)
    started = match.started
    if lifecycle.state is MatchState.STOPPING:
        _stop_robots(match)
        _read_counters(match)
        if started.simulator_id is not None:
            _guarded(match, "stopping the simulator", partial(
                match.runtime.stop, started.simulator_id,
                timeout_s=match.options.simulator_stop_s))
        for key, holder_id in started.holder_ids.items():
            _guarded(match, f"stopping the network holder of {key}",
                     partial(match.runtime.kill, holder_id))
        match.advance(MatchState.COLLECTING)
    if match.telemetry is not None:
        match.telemetry.close()
    match.monitor.join(timeout_s=1.0)
    for key, container_id in started.robot_ids.items():
        _team_guarded(match, key, f"collecting logs of {key}",
                      partial(_collect_robot, match, key, container_id))
    if started.simulator_id is not None and started.match_dir is not None:
        sim_id, match_dir = started.simulator_id, started.match_dir
        _guarded(match, "collecting simulator logs", lambda: match.runtime.save_logs(
            sim_id, stdout=match_dir / "stdout.log", stderr=match_dir / "stderr.log"))
    _guarded(match, "copying public files", lambda: _copy_public(match))


def _host_controls(match: MatchContext) -> dict[str, bool] | None:
    describe = getattr(match.host, "describe", None)
    return describe() if callable(describe) else None


def _version() -> str:
    try:
        return importlib.metadata.version("hlvs-runner")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def _spec_timing(match: MatchContext) -> TimingSpec | None:
    match_dir = match.started.match_dir
    if match_dir is None or not (match_dir / files.MATCH_SPEC).is_file():
        return None
    try:
        return MatchSpec.load(match_dir / files.MATCH_SPEC).timing
    except ContractError as exc:
        log.warning("match %s: %s", match.plan.match_id, exc)
        return None


def _write(match: MatchContext) -> MatchResults:
    out: Path = match.options.out_dir
    plan = match.plan
    limits = plan.limits
    sim_result = read_sim_result(match)
    if match.failure is None and match.forfeit is None:
        not_played = play_failure(sim_result, list(match.records.values()), _spec_timing(match))
        if not_played is not None:
            match.fail(not_played.failure_class, not_played.cause, team=not_played.team)
    results = build_results(
        match_id=plan.match_id,
        seed=plan.seed,
        sim_result=sim_result,
        robots=list(match.records.values()),
        forfeit=match.forfeit,
        limits=MatchLimits(
            cpus=limits.cpus, memory_gb=limits.memory_gb, pids=limits.pids,
            log_folder_gb=limits.log_folder_gb, team_api_mb_s=limits.team_api_mb_s,
            team_comm_mb_s=limits.team_comm_mb_s, grace_period_s=plan.grace_period_s,
            allow_internet=plan.allow_internet, host_controls=_host_controls(match),
        ),
        versions={"hlvs-runner": _version(), **plan.versions},
        timings_s=dict(match.lifecycle.timings_s),
        failure=match.failure,
        bringup_s=match.bringup_s,
        admission=plan.admission,
    )
    write_results(out, results)
    lifecycle = match.lifecycle
    if lifecycle.state is MatchState.COLLECTING:
        match.advance(MatchState.FAILED if match.failure else MatchState.DONE)
    elif lifecycle.state is MatchState.PENDING:
        match.advance(MatchState.FAILED)
    results = replace(results, timings_s=dict(lifecycle.timings_s))
    write_results(out, results)
    restrict(out)  # the teams' logs are theirs: owner-only, as everything else here
    write_report(out, match.failure, tuple(match.logs_cut))
    log.info("match %s: %s, results in %s", plan.match_id,
             "failed" if match.failure else "done", out)
    return results


class CollectionPhase:
    """STOPPING and COLLECTING from wherever the match got to; returns the results."""

    def __init__(self, match: MatchContext) -> None:
        self.match = match


    def run(self) -> MatchResults:
        """Stop, collect, remove everything created, write ``results.json`` and, last,
        ``report.json``; returns the results."""
        return _finish(self.match)


__all__ = ["PUBLIC_FILES", "CollectionPhase", "read_sim_result", "simulator_stderr_tail"]
