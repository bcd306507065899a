"""``hlvs match --pool slurm`` and ``hlvs scrimmage --pool slurm``: the match as a Slurm job.

The match is submitted through :class:`cluster.slurm.SlurmPool` (one batch job on a whole
node running ``hlvs match``), this command waits for it and shows Slurm's state and reason on
one line each time they change, then reads ``report.json`` / ``results.json`` from the usual
``--out`` folder and exits with the same codes as a local match. SIGINT / SIGTERM while waiting
cancel the job (``scancel``: the match stops gracefully) and wait for its report. Running this
command again with the same ``--out`` while the job is in Slurm adopts the job.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path
from typing import Any

from contracts import ContractError, FailureClass, MatchReport, MatchResults, files
from hlvs.commands.outcome import summarize
from orchestrator import InfrastructureError, stop_on_signals
from orchestrator.match import MatchOutcome

DEFAULT_CONF = "/var/lib/hlvs/slurm/slurm.conf"
POLL_S = 1.0


def make_pool(args: argparse.Namespace) -> Any:
    """The Slurm pool the options name; the output goes straight into ``--out``."""
    from cluster import HOST_NETNS, SlurmPool

    conf = args.slurm_conf or os.environ.get("SLURM_CONF") or DEFAULT_CONF
    # The one-machine cluster of 'hlvs pool up' shares this host's Docker engine: its jobs
    # enter the host's network namespace, which that script names (a real node has its own).
    return SlurmPool(slurm_conf=conf, host_network=Path(HOST_NETNS).exists(), out_subdir="")


def play_in_pool(
    args: argparse.Namespace, *, game_path: Path, match_id: str, out_dir: Path, official: bool,
    match_args: tuple[str, ...] = (), robot_nodes: int = 0,
) -> int:
    from cluster import JobState, MatchJob, PoolError

    pool = make_pool(args)
    as_json = bool(getattr(args, "json", False))
    try:
        handle = pool.recorded(out_dir)
        if handle is None or not pool.active(handle):
            for name in (files.REPORT, files.RESULTS):  # of an earlier run in this folder
                (out_dir / name).unlink(missing_ok=True)
            handle = pool.submit(MatchJob(
                match_id=match_id, game_path=game_path, work_dir=out_dir,
                account=getattr(args, "account", None), requeue=not official,
                match_args=match_args, robot_nodes=robot_nodes,
            ))
        job = pool.job_id(handle)
        _say(f"match {match_id}: Slurm job {job} submitted", as_json)
        shown = ""
        cancelled = False
        with stop_on_signals() as stop:
            while True:
                status = pool.status(handle)
                if status.state in (JobState.FINISHED, JobState.LOST):
                    break
                line = f"match {match_id}: Slurm job {job} {status.state.value}: {status.detail}"
                if line != shown:
                    _say(line, as_json)
                    shown = line
                if stop.is_set() and not cancelled:
                    pool.cancel(handle)
                    cancelled = True
                    _say(f"match {match_id}: Slurm job {job} cancelled, waiting for its "
                         "report", as_json)
                stop.wait(POLL_S)
    except PoolError as exc:
        raise InfrastructureError(f"Slurm pool: {exc}") from exc
    if not cancelled and _ended_early(status.state is JobState.LOST, out_dir) \
            and _final(pool, handle) == "NODE_FAIL":  # not requeued: an official match
        raise InfrastructureError(
            f"match {match_id}: its node failed (Slurm job {job}: NODE_FAIL); an official "
            f"match is not requeued, the operator decides; what it left is salvaged by "
            f"'hlvs cleanup --match {match_id}' into {out_dir}")
    if status.state is JobState.LOST:
        raise InfrastructureError(f"match {match_id}: {status.detail}; see "
                                  f"{out_dir}/slurm-{job}.out")
    return summarize(read_outcome(match_id, out_dir), as_json=as_json)


def _ended_early(lost: bool, out_dir: Path) -> bool:
    """No report, or one that says the match was interrupted (salvaged after its run died)."""
    if lost:
        return True
    try:
        report = MatchReport.load(out_dir / files.REPORT)
    except ContractError:
        return True
    return report.failure_class is FailureClass.INTERRUPTED


def _final(pool: Any, handle: str) -> str:
    deadline = time.monotonic() + 10  # the accounting database learns of the end a bit later
    while True:
        state = str(pool.final_state(handle))
        if state not in ("", "RUNNING", "PENDING", "REQUEUED") or time.monotonic() > deadline:
            return state
        time.sleep(1)


def read_outcome(match_id: str, out_dir: Path) -> MatchOutcome:
    """The outcome of a match played elsewhere, from the files it left in ``out_dir``."""
    results_path = out_dir / files.RESULTS
    try:
        report = MatchReport.load(out_dir / files.REPORT)
        results = MatchResults.load(results_path) if results_path.is_file() else None
    except ContractError as exc:
        raise InfrastructureError(f"match {match_id}: {exc}") from exc
    return MatchOutcome(match_id=match_id, failure=report.failure, out_dir=out_dir,
                        results=results, bringup_s=None)


def _say(line: str, as_json: bool) -> None:
    print(f"{time.strftime('%H:%M:%S')} {line}", file=sys.stderr if as_json else sys.stdout,
          flush=True)


__all__ = ["make_pool", "play_in_pool", "read_outcome"]
