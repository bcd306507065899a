"""STOPPING and COLLECTING: grace period, logs, public files, teardown, results, report.

:func:`collect` takes the match's dependencies, its lifecycle (moved on from wherever the match
got to), the ledger of what was created (:class:`~orchestrator.match.startup.Created`) and how
the game went (:class:`Played`), and returns the :class:`~contracts.match_results.MatchResults`
it wrote. It changes none of what it is given but the lifecycle: what it learns about the
robots, a failure of its own and the logs it had to cut are in the results and ``report.json``.

Every teardown step runs even when an earlier one failed; a teardown failure makes the match an
``infrastructure`` failure only when nothing else failed first. ``report.json`` is written last.

An engine that stops answering (:class:`~orchestrator.errors.EngineLost`: stopped, restarted or
crashed) is waited for, at most ``engine_wait_s`` in all, and the step that met it is tried
again: an engine that comes back still holds the stopped containers' consoles, which are
collected, and everything of the match is removed. The match fails naming the engine (a
simulator that ended as the engine went down is not blamed); an engine that does not come back
leaves the match's containers and networks on it, named in the cause with the command that
removes them.
"""

from __future__ import annotations

import importlib.metadata
import logging
import shutil
import threading
from collections.abc import Callable, Mapping
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from functools import partial
from pathlib import Path

from contracts import (
    ContractError,
    Forfeit,
    MatchLimits,
    MatchResults,
    MatchSpec,
    SimResult,
    TimingSpec,
    files,
)
from orchestrator.errors import EngineLost, OrchestratorError
from orchestrator.match import gate, layout
from orchestrator.match.deps import MatchDeps
from orchestrator.match.logfs import LogFolder
from orchestrator.match.results import (
    Failure,
    FailureClass,
    RobotRecord,
    build_results,
    play_failure,
    write_report,
    write_results,
)
from orchestrator.match.safecopy import restrict
from orchestrator.match.startup import Created, read_gated_counters
from orchestrator.match.state import Lifecycle, MatchState
from orchestrator.runtime.port import ContainerRuntime

log = logging.getLogger(__name__)

PUBLIC_FILES = files.PUBLIC_FILES


@dataclass(frozen=True, slots=True, kw_only=True)
class Played:
    """How the match went until it stopped (or before it could start): what collection
    starts from."""

    robots: Mapping[str, RobotRecord]  # robot key -> its image, its start, its exit in the game
    failure: Failure | None  # the match's failure so far (announced), None: none yet
    forfeit: Forfeit | None  # a team without a usable image (the match was not played)
    bringup_s: float | None  # start of STARTING -> every robot connected (from telemetry)


def collect(deps: MatchDeps, lifecycle: Lifecycle, created: Created, played: Played
            ) -> MatchResults:
    """Stop, collect, remove everything in ``created``, write ``results.json`` and, last,
    ``report.json``; returns the results (their ``failure`` is the match's: ``played``'s, else
    the first one collection met). ``lifecycle`` ends in DONE or FAILED. The teardown and the
    match record happen whatever breaks before them."""
    return _Collection(deps, lifecycle, created, played).run()


def reserve_space(out: Path) -> None:
    """Space the runner keeps in the output folder from the start for ``results.json`` and
    ``report.json`` (tens of KB), given back just before they are written: a disk that fills
    during the match still takes the match's outcome (a disk already too full gets none)."""
    files.reserve_space(out, log)


def read_sim_result(match_dir: Path | None, *, match_id: str) -> SimResult | None:
    """The simulator's ``sim_result.json`` in ``match_dir``; None when it is missing or does
    not fit the contract (logged with the file, field and reason)."""
    if match_dir is None:
        return None
    path = match_dir / files.OUT_DIR / files.SIM_RESULT
    if not path.exists():
        return None
    try:
        return SimResult.load(path)
    except ContractError as exc:
        log.error("match %s: %s", match_id, exc)
        return None


def simulator_stderr_tail(runtime: ContainerRuntime, simulator_id: str | None,
                          match_dir: Path | None) -> str:
    """The last line of the simulator's stderr (its console saved into ``match_dir``)."""
    if simulator_id is None or match_dir is None:
        return ""
    try:
        runtime.save_logs(simulator_id, stdout=match_dir / "stdout.log",
                          stderr=match_dir / "stderr.log")
        lines = (match_dir / "stderr.log").read_text(errors="replace").strip().splitlines()
    except (OrchestratorError, OSError):
        return ""
    return lines[-1][:300] if lines else ""


class _Collection:
    """One run of :func:`collect`: its own copies of the robots' records, the failure and the
    logs cut, which end up in the results and the report."""

    def __init__(self, deps: MatchDeps, lifecycle: Lifecycle, created: Created,
                 played: Played) -> None:
        self.deps = deps
        self.lifecycle = lifecycle
        self.created = created
        self.played = played
        self.records = {key: replace(r) for key, r in played.robots.items()}
        self.failure = played.failure
        # the teams' logs cut or lost in collection: {"robot", "what", "reason"} (report.json)
        self.logs_cut: list[dict[str, str]] = []
        self.engine_lost: EngineLost | None = None  # the engine stopped answering meanwhile
        self.engine_deadline = 0.0  # until when it is waited for (clock time)
        self._engine_lock = threading.Lock()  # robots are stopped in parallel

    def run(self) -> MatchResults:
        match_id = self.deps.plan.match_id
        try:
            self._stop_and_collect()
        except Exception as exc:  # noqa: BLE001 - the record is written and everything removed
            log.exception("match %s: collection failed", match_id)
            self._fail(f"collection failed: {type(exc).__name__}: {exc}")
        try:
            self._teardown()
        except Exception as exc:  # noqa: BLE001
            log.exception("match %s: teardown failed", match_id)
            self._fail(f"teardown failed: {type(exc).__name__}: {exc}")
        if self.engine_lost is not None and not self.deps.runtime.answering():
            self._engine_gone()
        return self._write()

    def _engine_back(self, lost: EngineLost) -> bool:
        """The engine stopped answering: the match fails naming it, and it is waited for (at
        most ``engine_wait_s`` over the whole collection). True: it answers again."""
        deps = self.deps
        with self._engine_lock:
            self._engine_first_lost(lost)
        wait = threading.Event()
        while not deps.runtime.answering():
            if deps.clock() >= self.engine_deadline:
                return False
            wait.wait(deps.options.poll_s)
        return True

    def _engine_first_lost(self, lost: EngineLost) -> None:
        deps = self.deps
        if self.engine_lost is None:
            self.engine_lost = lost
            self.engine_deadline = deps.clock() + deps.options.engine_wait_s
            log.warning("match %s: %s; waiting up to %.0f s for it to answer again",
                        deps.plan.match_id, lost, deps.options.engine_wait_s)
            if self.failure is not None and self.failure.failure_class is FailureClass.SIMULATOR:
                # the simulator ended as the engine went down: the engine stopped it
                log.info("match %s: the simulator's end (%s) was the engine's doing",
                         deps.plan.match_id, self.failure.cause)
                self.failure = deps.fail(None, FailureClass.INFRASTRUCTURE, (
                    f"{lost}; it stopped the match's containers (the simulator's end: "
                    f"{self.failure.cause})"))
            else:
                self._fail(str(lost))

    def _engine_gone(self) -> None:
        """The engine never answered again: what the match left on it is named."""
        deps, match_id = self.deps, self.deps.plan.match_id
        left = (f"the engine did not answer again within {deps.options.engine_wait_s:.0f} s: "
                f"the match's containers and networks are left on it; `hlvs cleanup --match "
                f"{match_id}` removes them once it answers")
        log.error("match %s: %s", match_id, left)
        if self.failure is not None and self.failure.failure_class is FailureClass.INFRASTRUCTURE:
            self.failure = replace(self.failure, cause=f"{self.failure.cause}; {left}")

    def _engine_step(self, step: Callable[[], object]) -> None:
        """``step``, again each time the engine came back after it met the engine gone away
        (a restarting engine may answer a ping before it serves every call), until the wait
        for the engine (``engine_wait_s``) is over."""
        while True:
            try:
                step()
                return
            except EngineLost as exc:
                if not self._engine_back(exc):
                    raise
                if self.deps.clock() >= self.engine_deadline:
                    step()  # the last try: its error is the step's
                    return
                threading.Event().wait(max(self.deps.options.poll_s, 0.1))

    def _fail(self, cause: str) -> None:
        self.failure = self.deps.fail(self.failure, FailureClass.INFRASTRUCTURE, cause)

    def _guarded(self, what: str, step: Callable[[], object]) -> None:
        """Run one step of stopping, collecting or teardown; a failure fails the match (the
        first one counts) and the next steps still run."""
        try:
            self._engine_step(step)
        except (OrchestratorError, OSError) as exc:
            log.error("match %s: %s failed: %s", self.deps.plan.match_id, what, exc)
            self._fail(f"{what}: {exc}")
        except Exception as exc:  # noqa: BLE001 - the steps after this one must still run
            log.exception("match %s: %s failed", self.deps.plan.match_id, what)
            self._fail(f"{what}: {type(exc).__name__}: {exc}")

    def _team_guarded(self, key: str, what: str, step: Callable[[], object]) -> None:
        """A step that touches what a robot made: an engine failure fails the match (as
        :meth:`_guarded`), anything else costs only this robot's logs, named in report.json."""
        try:
            self._engine_step(step)
        except (OrchestratorError, OSError) as exc:
            log.error("match %s: %s failed: %s", self.deps.plan.match_id, what, exc)
            self._fail(f"{what}: {exc}")
        except Exception as exc:  # noqa: BLE001 - a robot's output never breaks the match record
            log.exception("match %s: %s failed", self.deps.plan.match_id, what)
            self.logs_cut.append({"robot": key, "what": what,
                                  "reason": f"{type(exc).__name__}: {exc}"})

    # STOPPING and COLLECTING --------------------------------------------------------------
    def _stop_and_collect(self) -> None:
        deps, created, lifecycle = self.deps, self.created, self.lifecycle
        if lifecycle.state in (MatchState.PULLING, MatchState.STARTING, MatchState.WAITING,
                               MatchState.PLAYING):
            lifecycle.advance(MatchState.STOPPING)
        if lifecycle.state is MatchState.STOPPING:
            self._stop_robots()
            self._read_counters()
            if created.simulator_id is not None:
                self._guarded("stopping the simulator", partial(
                    deps.runtime.stop, created.simulator_id,
                    timeout_s=deps.options.simulator_stop_s))
            for key, holder_id in created.holder_ids.items():
                self._guarded(f"stopping the network holder of {key}",
                              partial(deps.runtime.kill, holder_id))
            lifecycle.advance(MatchState.COLLECTING)
        deps.monitor.join(timeout_s=1.0)
        for key, container_id in created.robot_ids.items():
            self._team_guarded(key, f"collecting logs of {key}",
                               partial(self._collect_robot, key, container_id))
        if created.simulator_id is not None and created.match_dir is not None:
            sim_id, match_dir = created.simulator_id, created.match_dir
            self._guarded("collecting simulator logs", lambda: deps.runtime.save_logs(
                sim_id, stdout=match_dir / "stdout.log", stderr=match_dir / "stderr.log"))
        self._guarded("copying public files", self._copy_public)

    def _stop_robots(self) -> None:
        deps = self.deps
        grace = deps.plan.grace_period_s
        ids = self.created.robot_ids

        def stop(item: tuple[str, str]) -> None:
            key, container_id = item
            # a gated robot's namespace (and its counters) ends with its container: the last
            # reading is taken as it is asked to stop
            read_gated_counters(deps, self.created, key)
            self._guarded(f"stopping robot {key}",
                          lambda: deps.runtime.stop(container_id, timeout_s=grace))

        if ids:
            log.info("match %s: stopping %d robots (grace %.0f s)", deps.plan.match_id,
                     len(ids), grace)
            with ThreadPoolExecutor(max_workers=min(8, len(ids))) as pool:
                list(pool.map(stop, ids.items()))

    def _read_counters(self) -> None:
        created = self.created
        for key, applied in created.shaping.items():
            record = self.records[key]
            if key in created.gated:  # read while it ran (runner) and as it was stopped
                if key not in created.counters:
                    log.warning("match %s: no traffic counters for %s (its network ended "
                                "before they were read)", self.deps.plan.match_id, key)
                    continue
                counters = created.counters[key]
            else:
                try:
                    counters = self.deps.host.counters(applied)
                except OrchestratorError as exc:
                    log.warning("match %s: no traffic counters for %s: %s",
                                self.deps.plan.match_id, key, exc)
                    continue
            record.entry = replace(record.entry, sent_bytes=counters.sent_bytes,
                                   received_bytes=counters.received_bytes)

    def _collect_robot(self, key: str, container_id: str) -> None:
        deps = self.deps
        record = self.records[key]
        folder = deps.options.out_dir / "teams" / record.color / str(record.number)
        state = deps.runtime.inspect(container_id)
        peaks = deps.monitor.peaks(key)
        record.entry = replace(record.entry, exit_code=state.exit_code,
                               oom_killed=record.entry.oom_killed or state.oom_killed,
                               restarts=state.restart_count, cpu_peak_percent=peaks.cpu_percent,
                               memory_peak_bytes=peaks.memory_bytes)
        cap = layout.ROBOT_CONSOLE_BYTES // 2  # per stream (the engine keeps less of a flood)
        cut = deps.runtime.save_logs(container_id, stdout=folder / "stdout.log",
                                     stderr=folder / "stderr.log", max_bytes=cap)
        for stream in cut:
            self.logs_cut.append({"robot": key, "what": f"{stream}.log",
                                  "reason": f"cut at the limit of {cap} bytes"})

    def _copy_public(self) -> None:
        match_dir = self.created.match_dir
        public = self.deps.options.out_dir / "public"
        public.mkdir(parents=True, exist_ok=True)
        if match_dir is None:
            return
        for name in PUBLIC_FILES:
            source = match_dir / files.OUT_DIR / name
            if source.is_file():
                shutil.copy2(source, public / name)

    # teardown -----------------------------------------------------------------------------
    def _teardown(self) -> None:
        deps, created = self.deps, self.created
        runtime, host = deps.runtime, deps.host
        for key, container_id in (list(created.robot_ids.items())
                                  + list(created.holder_ids.items())):
            self._guarded(f"removing container of {key}", partial(runtime.remove, container_id))
        if created.simulator_id is not None:
            sim_id = created.simulator_id
            self._guarded("removing the simulator", lambda: runtime.remove(sim_id))
        # the folders the robots' start gates waited in (also of robots never shaped)
        shutil.rmtree(deps.options.out_dir / gate.FOLDERS, ignore_errors=True)
        for key, folder in created.log_folders.items():
            record = self.records[key]
            target = deps.options.out_dir / "teams" / record.color / str(record.number)
            self._team_guarded(key, f"releasing /robocup-logs of {key}", partial(
                self._collect_log_folder, key, folder, target / "robocup-logs"))
        for key, scratch in created.scratch.items():
            self._guarded(f"releasing the scratch space of {key}", partial(host.release, scratch))
        for applied in created.node_shaping:  # league placement: the nodes outlive the match
            self._guarded(f"removing the bandwidth limits of {applied.netns}",
                          partial(host.unshape, applied))
        for netns in created.node_firewalls:
            self._guarded(f"removing the robot node firewall of {netns}",
                          partial(host.remove_node_firewall, netns))
        for network in created.networks.values():
            self._guarded(f"removing network {network.name}",
                          partial(runtime.remove_network, network.name))
        self._guarded("removing host firewall rules",
                      lambda: host.remove_isolation(match_id=deps.plan.match_id))

    def _collect_log_folder(self, key: str, folder: LogFolder, destination: Path) -> None:
        """What a team wrote never fails the match: only releasing the mount can raise."""
        deps = self.deps
        limit = int(deps.plan.limits.log_folder_gb * 1e9)
        report = deps.host.collect_logs(folder, destination, limit_bytes=limit)
        record = self.records[key]
        record.entry = replace(record.entry, log_folder=report.record())
        if report.stopped:
            self.logs_cut.append({"robot": key, "what": "robocup-logs",
                                  "reason": report.stopped})
        if report.skipped_count:
            log.warning("match %s: %s: %d entries of /robocup-logs not collected (%s)",
                        deps.plan.match_id, key, report.skipped_count,
                        ", ".join(f"{s['path']}: {s['kind']}" for s in report.skipped[:5]))

    # the match record ---------------------------------------------------------------------
    def _write(self) -> MatchResults:
        deps, lifecycle = self.deps, self.lifecycle
        out: Path = deps.options.out_dir
        plan = deps.plan
        limits = plan.limits
        sim_result = read_sim_result(self.created.match_dir, match_id=plan.match_id)
        robots = list(self.records.values())
        if self.failure is None and self.played.forfeit is None:
            not_played = play_failure(sim_result, robots, self._spec_timing())
            if not_played is not None:
                self.failure = deps.fail(None, not_played.failure_class, not_played.cause,
                                         team=not_played.team)
        results = build_results(
            match_id=plan.match_id,
            seed=plan.seed,
            sim_result=sim_result,
            robots=robots,
            forfeit=self.played.forfeit,
            limits=MatchLimits(
                cpus=limits.cpus, memory_gb=limits.memory_gb, pids=limits.pids,
                log_folder_gb=limits.log_folder_gb, team_api_mb_s=limits.team_api_mb_s,
                team_comm_mb_s=limits.team_comm_mb_s, grace_period_s=plan.grace_period_s,
                allow_internet=plan.allow_internet, host_controls=self._host_controls(),
            ),
            versions={"hlvs-runner": _version(), **plan.versions},
            timings_s=dict(lifecycle.timings_s),
            failure=self.failure,
            bringup_s=self.played.bringup_s,
            admission=plan.admission,
        )
        (out / files.RESERVE_FILE).unlink(missing_ok=True)  # its space is the results'
        write_results(out, results)
        if lifecycle.state is MatchState.COLLECTING:
            lifecycle.advance(MatchState.FAILED if self.failure else MatchState.DONE)
        elif lifecycle.state is MatchState.PENDING:
            lifecycle.advance(MatchState.FAILED)
        results = replace(results, timings_s=dict(lifecycle.timings_s))
        write_results(out, results)
        restrict(out)  # the teams' logs are theirs: owner-only, as everything else here
        write_report(out, self.failure, tuple(self.logs_cut))
        log.info("match %s: %s, results in %s", plan.match_id,
                 "failed" if self.failure else "done", out)
        return results

    def _host_controls(self) -> dict[str, bool] | None:
        describe = getattr(self.deps.host, "describe", None)
        return describe() if callable(describe) else None

    def _spec_timing(self) -> TimingSpec | None:
        match_dir = self.created.match_dir
        if match_dir is None or not (match_dir / files.MATCH_SPEC).is_file():
            return None
        try:
            return MatchSpec.load(match_dir / files.MATCH_SPEC).timing
        except ContractError as exc:
            log.warning("match %s: %s", self.deps.plan.match_id, exc)
            return None


def _version() -> str:
    try:
        return importlib.metadata.version("hlvs-runner")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


__all__ = ["PUBLIC_FILES", "Played", "collect", "read_sim_result", "simulator_stderr_tail"]
