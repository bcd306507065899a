"""The Slurm pool: each match is one Slurm batch job that runs ``hlvs match`` on a node.

Dense placement: a job takes one whole node (``--exclusive``, ``-N1``), so matches run side by
side across the cluster's nodes and Slurm queues the rest. A team's test matches are submitted
under the team's Slurm account (``sbatch --account``), so the account's limits (``GrpJobs=1``:
one running match per team; ``MaxSubmitJobs``: a bounded queue) and its QOS apply; Slurm gives
the reason a job waits and its expected start (``squeue``), which :meth:`SlurmPool.queue`
returns for ``hlvs pool status``.

Slurm does not control the Docker containers a match starts, so the job runs ``hlvs match``
itself as the batch step (``exec``): ``scancel`` sends it SIGTERM, which stops the match
gracefully (robots get their grace period, logs are collected, ``report.json`` says
``interrupted``); the cluster's ``KillWait`` must be longer than that (150 s in the cluster that
``scripts/ensure-slurm.sh`` sets up).

A test match (``MatchJob.requeue``) is submitted with ``--requeue``: when its node fails, Slurm
puts it back in the queue and plays it again on another node (the new ``hlvs match`` salvages
what the dead run left and plays the match from the start); official matches get
``--no-requeue`` and wait for the operator.

The handle is ``slurm:<job id>:<work folder>``; ``<work folder>/slurm.json`` remembers the job
so that a second submit of the same match adopts it (:meth:`SlurmPool.recorded`).
This is the only module that runs Slurm's commands.
"""

from __future__ import annotations

import json
import logging
import os
import shlex
import subprocess
import sys
import time
from collections.abc import Iterable
from dataclasses import dataclass, replace
from pathlib import Path

from cluster import JobState, JobStatus, MatchJob
from cluster.errors import PoolError
from cluster.nodes import (
    ENV_REMOTE_COMMENT,
    SINFO_FORMAT,
    SQUEUE_NODES_FORMAT,
    PoolNode,
    match_of_job_name,
    parse_sinfo,
    parse_squeue_nodes,
)
from contracts import files

log = logging.getLogger(__name__)

QUEUE_FORMAT = "%i|%j|%a|%T|%r|%S|%N|%k"  # id, name, account, state, reason, start, nodes, comment

STATE_FILE = "slurm.json"
HOST_NETNS = "/run/netns/hlvs-host"  # named by scripts/ensure-slurm.sh
NODE_NETNS = "/run/netns/hlvs-{node}"  # each node's network namespace, same script
LOG_FILE = "slurm-%j.out"
ACTIVE = {"PENDING", "CONFIGURING", "RUNNING", "COMPLETING", "SUSPENDED", "REQUEUED",
          "RESIZING", "SIGNALING", "STAGE_OUT"}


@dataclass(frozen=True, slots=True, kw_only=True)
class QueueEntry:
    """A match job as Slurm sees it."""

    job_id: str
    name: str
    account: str
    state: str  # PENDING, RUNNING, ...
    reason: str  # why it waits (Priority, Resources, AssocGrpJobsLimit...) or "None"
    expected_start: str  # ISO time Slurm expects it to start (pending), or when it started
    nodes: str
    comment: str = ""

    @property
    def kind(self) -> str:
        """``match``, or ``environment`` for a learning environment's remote."""
        return "environment" if self.comment == ENV_REMOTE_COMMENT else "match"

    def to_json(self) -> dict[str, str | None]:
        return {
            "job_id": self.job_id, "kind": self.kind,
            "match_id": match_of_job_name(self.name, self.comment), "account": self.account,
            "state": self.state, "reason": self.reason, "expected_start": self.expected_start,
            "nodes": self.nodes,
        }


class SlurmPool:
    def __init__(
        self, *, slots: int = 3, partition: str | None = None, slurm_conf: str | None = None,
        python: str = sys.executable, extra_args: tuple[str, ...] = (), qos: str | None = None,
        host_network: bool = False, out_subdir: str = "out",
    ) -> None:
        self.slots = slots
        self.partition = partition
        self.slurm_conf = slurm_conf
        self.python = python
        self.extra_args = extra_args
        self.qos = qos
        # Nodes of the one-machine cluster share this host's Docker engine, whose networks
        # live in the host's network namespace: the match enters it (a real node has its own).
        self.host_network = host_network
        # The match output goes to <work>/<out_subdir> (the work folder itself when empty).
        self.out_subdir = out_subdir

    # MatchPool ---------------------------------------------------------------------------
    def submit(self, job: MatchJob) -> str:
        work = job.work_dir.resolve()
        previous = self._recorded(work)
        if previous is not None and self._squeue_state(previous) in ACTIVE:
            log.info("match %s already in Slurm as job %s; adopted", job.match_id, previous)
            return self._handle(previous, work)
        out = work / self.out_subdir if self.out_subdir else work
        out.mkdir(parents=True, exist_ok=True)
        script = self._script(job, out)
        args = self._batch_args(name=f"hlvs-{job.match_id}", work=work, requeue=job.requeue)
        account = job.account
        # dense: one whole node; league: a heterogeneous job, the simulator's node (component
        # 0, where the batch script runs) and a node for each robot, allocated together
        components = [["--constraint=sim"] if job.robot_nodes else []]
        components += [["--constraint=robot"] for _ in range(job.robot_nodes)]
        for index, component in enumerate(components):
            if index:
                args.append(":")
            args += ["--exclusive", "-N1", *component, *self._placement_args(account)]
        job_id = self._sbatch(args, script, work)
        tmp = work / (STATE_FILE + ".tmp")
        tmp.write_text(json.dumps({"job_id": job_id, "match_id": job.match_id,
                                   "account": account}))
        tmp.replace(work / STATE_FILE)
        log.info("match %s submitted to Slurm as job %s (account %s)", job.match_id, job_id,
                 account or "default")
        return self._handle(job_id, work)

    def submit_script(self, script: str, *, name: str, work: Path, requeue: bool = False,
                      account: str | None = None, cpus: int | None = None,
                      comment: str | None = None) -> str:
        """Submit ``script`` as one batch job named ``name``, run in ``work`` (its output in
        ``work/slurm-<job>.out``), on a whole node (``--exclusive -N1``) or, with ``cpus``, as
        one task of that many CPUs (a partition may still give it a whole node); the job id."""
        share = ["--exclusive"] if cpus is None else ["-n1", f"--cpus-per-task={cpus}"]
        args = [*self._batch_args(name=name, work=work, requeue=requeue), *share, "-N1",
                *self._placement_args(account)]
        if comment:
            args.append(f"--comment={comment}")
        return self._sbatch(args, script, work)

    def entries(self, job_ids: list[str]) -> dict[str, QueueEntry]:
        """What Slurm's queue says of these jobs (one ``squeue``); ended jobs are absent."""
        if not job_ids:
            return {}
        text = self._run(["squeue", "-h", "-j", ",".join(job_ids), "-o",
                          QUEUE_FORMAT], handle=",".join(job_ids), ok_codes=(0, 1))
        found = (_parse_entry(line) for line in text.splitlines() if "|" in line)
        return {e.job_id: e for e in found if e.job_id in job_ids}

    def cancel_jobs(self, job_ids: list[str]) -> None:
        """``scancel``: SIGTERM to each job's processes (``KillWait`` later, SIGKILL)."""
        if job_ids:
            self._run(["scancel", *job_ids], handle=",".join(job_ids))

    def accounting_state(self, job_id: str) -> str:
        """``State|ExitCode`` of a job from Slurm's accounting (empty when unknown)."""
        return self._sacct_state(job_id)

    def _script(self, job: MatchJob, out: Path) -> str:
        """The batch script. A requeued run (``SLURM_RESTART_COUNT`` > 0) first salvages what
        the dead run left (``hlvs cleanup --match``: logs into the output folder, containers
        and networks removed) and moves that attempt's files to ``attempt-<n>/``, then plays
        the match from the start."""
        prefix = ["nsenter", f"--net={HOST_NETNS}"] if self.host_network else []
        hlvs = [*prefix, self.python, "-m", "hlvs", *self.extra_args]
        play = [*hlvs, "match", str(job.game_path.resolve()), "--out", str(out),
                *job.match_args]
        nodes: list[str] = []
        if job.robot_nodes:
            play += ["--placement", "league", "--league-nodes", "$nodes"]
            if self.host_network:
                play += ["--node-netns", NODE_NETNS]
            nodes = [  # NAME=ADDRESS of each component's node, the simulator's first
                'nodes=""',
                f"for group in $(seq 0 {job.robot_nodes}); do",
                '  eval "list=\\${SLURM_JOB_NODELIST_HET_GROUP_$group:-}"',
                '  name=$(scontrol show hostnames "$list" | head -n 1)',
                '  addr=$(scontrol show node "$name" -o | tr " " "\\n" | '
                "sed -n 's/^NodeAddr=//p')",
                '  nodes="$nodes${nodes:+,}$name=$addr"',
                "done",
                # a step on each robot node holds it while its robot runs: cancelled (or the
                # job ending), it stops the node's robot with a grace period (also when the
                # match's orchestrator died) and leaves the match a moment to collect its logs,
                # instead of the node ending at once and its epilog removing the robot
                'export HLVS_SLURM_JOB="$SLURM_JOB_ID"',
                "keeper=$(cat <<'KEEP'",
                *_KEEPER.splitlines(),
                "KEEP",
                ")",
                f"for group in $(seq 1 {job.robot_nodes}); do",
                '  srun --het-group="$group" -N1 -n1 --quiet sh -c "$keeper" &',
                "done",
            ]
        keep = ["slurm.json", "slurm-*.out", "config", "attempt-*"]
        game = job.game_path.resolve()
        if game.is_relative_to(out) and game != out:
            keep.append(game.relative_to(out).parts[0])
        q = shlex.quote
        return "\n".join([
            "#!/bin/sh",
            'if [ "${SLURM_RESTART_COUNT:-0}" -gt 0 ]; then',
            f"  {' '.join(q(c) for c in hlvs)} cleanup --match {q(job.match_id)}",
            f'  attempt={q(str(out))}/attempt-"$SLURM_RESTART_COUNT"',
            '  mkdir -p "$attempt"',
            f"  for f in {q(str(out))}/*; do",
            f'    case "${{f##*/}}" in {"|".join(q(k) if "*" not in k else k for k in keep)}) ;;',
            '      *) mv "$f" "$attempt"/ ;;',
            "    esac",
            "  done",
            "fi",
            *nodes,
            "exec " + " ".join('"$nodes"' if c == "$nodes" else q(c) for c in play),
            "",
        ])

    def status(self, handle: str) -> JobStatus:
        job_id, work = self._parse(handle)
        entry = self._entry(job_id)
        if entry is not None and entry.state in ACTIVE:
            if entry.state == "PENDING":
                detail = f"waiting in Slurm: {entry.reason}"
                if entry.expected_start not in ("N/A", ""):
                    detail += f", expected start {entry.expected_start}"
                return JobStatus(state=JobState.PENDING, detail=detail)
            return JobStatus(state=JobState.RUNNING, detail=f"on {entry.nodes}")
        if (self.results_dir(handle) / files.REPORT).is_file():
            return JobStatus(state=JobState.FINISHED)
        final = self._sacct_state(job_id)
        return JobStatus(state=JobState.LOST,
                         detail=f"Slurm job {job_id} ended ({final or 'unknown state'}) "
                         "without a report.json")

    def cancel(self, handle: str) -> None:
        job_id, work = self._parse(handle)
        self._run(["scancel", job_id], handle=handle)
        log.info("Slurm job %s of %s cancelled (SIGTERM: graceful stop)", job_id, work)

    def results_dir(self, handle: str) -> Path:
        work = self._parse(handle)[1]
        return work / self.out_subdir if self.out_subdir else work

    def recorded(self, work_dir: Path) -> str | None:
        """The handle of the job last submitted for ``work_dir`` (running or not), or None."""
        work = work_dir.resolve()
        job_id = self._recorded(work)
        return None if job_id is None else self._handle(job_id, work)

    def active(self, handle: str) -> bool:
        """Whether Slurm still has the job (pending, running, requeued...)."""
        return self._squeue_state(self._parse(handle)[0]) in ACTIVE

    def job_id(self, handle: str) -> str:
        return self._parse(handle)[0]

    def final_state(self, handle: str) -> str:
        """Slurm's accounting state of an ended job (COMPLETED, CANCELLED, NODE_FAIL...)."""
        return self._sacct_state(self._parse(handle)[0]).split("|")[0].split(" ")[0]

    # queue for hlvs pool status ------------------------------------------------------------
    def queue(self) -> list[QueueEntry]:
        """Every match job Slurm knows of (pending first), with its reason and expected start."""
        text = self._run(["squeue", "-h", "-o", QUEUE_FORMAT], handle="squeue")
        entries = _merged(_parse_entry(line) for line in text.splitlines() if line.strip())
        return sorted((e for e in entries if e.name.startswith("hlvs-")),
                      key=lambda e: (e.state != "PENDING", e.job_id))

    def nodes(self) -> list[PoolNode]:
        """The cluster's nodes (``sinfo``): state, the reason a node is drained or down, its
        features, CPUs and memory, and the jobs running on it (``squeue``)."""
        listed = self._run(["sinfo", "-N", "-h", "-o", SINFO_FORMAT], handle="sinfo")
        running = self._run(["squeue", "-h", "-o", SQUEUE_NODES_FORMAT], handle="squeue")
        try:
            nodes = parse_sinfo(listed)
            jobs = parse_squeue_nodes(running)
        except ValueError as exc:
            raise PoolError(handle="sinfo", reason=str(exc)) from exc
        return [replace(n, jobs=tuple(jobs.get(n.name, ()))) for n in nodes]

    def ensure_account(self, name: str, *, max_running: int = 1, max_queued: int = 5) -> None:
        """A Slurm account for a team (idempotent): at most ``max_running`` of its jobs run
        (``GrpJobs``) and at most ``max_queued`` are accepted (``MaxSubmitJobs``); root may
        submit under it (the pool submits for the teams)."""
        self._run(["sacctmgr", "-i", "add", "account", name], handle=name, ok_codes=(0, 1))
        self._run(["sacctmgr", "-i", "modify", "account", name, "set",
                   f"GrpJobs={max_running}", f"MaxSubmitJobs={max_queued}"], handle=name,
                  ok_codes=(0, 1))
        self._run(["sacctmgr", "-i", "add", "user", "root", f"account={name}"], handle=name,
                  ok_codes=(0, 1))
        deadline = time.monotonic() + 30  # the controller learns of it from the database
        while time.monotonic() < deadline:
            shown = self._run(["scontrol", "show", "assoc_mgr", "users=root", f"accounts={name}",
                               "flags=assoc"], handle=name, ok_codes=(0, 1))
            if f"Account={name} " in shown and "UserName=root" in shown:
                return
            time.sleep(0.5)
        raise PoolError(handle=name, reason="the Slurm controller did not learn of the account")

    # helpers -----------------------------------------------------------------------------
    @staticmethod
    def _handle(job_id: str, work: Path) -> str:
        return f"slurm:{job_id}:{work}"

    @staticmethod
    def _parse(handle: str) -> tuple[str, Path]:
        kind, job_id, work = (handle.split(":", 2) + ["", ""])[:3]
        if kind != "slurm" or not job_id.isdigit() or not work:
            raise PoolError(handle=handle, reason="not a Slurm pool handle (slurm:<job>:<dir>)")
        return job_id, Path(work)

    def _recorded(self, work: Path) -> str | None:
        try:
            data = json.loads((work / STATE_FILE).read_text())
        except (OSError, ValueError):
            return None
        job_id = data.get("job_id") if isinstance(data, dict) else None
        return job_id if isinstance(job_id, str) else None

    def _entry(self, job_id: str) -> QueueEntry | None:
        text = self._run(["squeue", "-h", "-j", job_id, "-o", QUEUE_FORMAT],
                         handle=job_id, ok_codes=(0, 1))
        entries = _merged(_parse_entry(line) for line in text.splitlines() if line.strip())
        return next((e for e in entries if e.job_id == job_id), None)

    def _squeue_state(self, job_id: str) -> str | None:
        entry = self._entry(job_id)
        return None if entry is None else entry.state

    def _sacct_state(self, job_id: str) -> str:
        text = self._run(["sacct", "-n", "-X", "-P", "-j", job_id, "-o", "State,ExitCode"],
                         handle=job_id, ok_codes=(0, 1))
        return text.strip().splitlines()[0] if text.strip() else ""

    @staticmethod
    def _batch_args(*, name: str, work: Path, requeue: bool) -> list[str]:
        """``sbatch`` for one job named ``name``, run in ``work`` (its output appended to
        ``work/slurm-<job>.out``)."""
        return ["sbatch", "--parsable", f"--job-name={name}", f"--chdir={work}",
                f"--output={work / LOG_FILE}", "--open-mode=append",
                "--requeue" if requeue else "--no-requeue"]

    def _placement_args(self, account: str | None) -> list[str]:
        """The partition, account and QOS a job (or each component of a het job) runs under."""
        return [*([f"--partition={self.partition}"] if self.partition else []),
                *([f"--account={account}"] if account else []),
                *([f"--qos={self.qos}"] if self.qos else [])]

    def _sbatch(self, args: list[str], script: str, work: Path) -> str:
        """Submit; the job id ``sbatch --parsable`` answers."""
        result = self._run(args, stdin=script, handle=str(work))
        job_id = result.strip().split(";")[0]
        if not job_id.isdigit():
            raise PoolError(handle=str(work), reason=f"sbatch answered {result.strip()!r}")
        return job_id

    def _run(self, args: list[str], *, handle: str, stdin: str | None = None,
             ok_codes: tuple[int, ...] = (0,)) -> str:
        env = dict(os.environ)
        if self.slurm_conf:
            env["SLURM_CONF"] = self.slurm_conf
        try:
            result = subprocess.run(args, input=stdin, capture_output=True, text=True,
                                    env=env, timeout=60, check=False)
        except (OSError, subprocess.TimeoutExpired) as exc:
            raise PoolError(handle=handle, reason=f"{args[0]} failed: {exc}") from exc
        if result.returncode not in ok_codes:
            raise PoolError(handle=handle, reason=f"{' '.join(args[:2])}: exit "
                            f"{result.returncode}: {result.stderr.strip()[-300:]}")
        return result.stdout


_KEEPER = """\
mine="--filter label=org.hlvs-runner.slurm-job=$HLVS_SLURM_JOB"
mine="$mine --filter label=org.hlvs-runner.node=$SLURMD_NODENAME"
stop() {
  robots=$(docker ps -q $mine --filter label=org.hlvs-runner.role=robot)
  [ -z "$robots" ] || docker stop -t 120 $robots >/dev/null 2>&1
  n=0
  while [ $n -lt 30 ] && [ -n "$(docker ps -aq $mine)" ]; do sleep 0.5; n=$((n + 1)); done
  exit 0
}
trap stop TERM INT
while :; do sleep 1 & wait $!; done"""


def _merged(entries: Iterable[QueueEntry]) -> list[QueueEntry]:
    """One entry per job: the components of a heterogeneous job (``<id>+<k>``, league
    placement) as one, with the nodes of all of them (the simulator's first)."""
    merged: dict[str, QueueEntry] = {}
    for entry in entries:
        base = entry.job_id.split("+")[0]
        first = merged.get(base)
        if first is None:
            merged[base] = replace(entry, job_id=base)
        elif entry.nodes:
            merged[base] = replace(first, nodes=",".join(n for n in (first.nodes, entry.nodes)
                                                         if n))
    return list(merged.values())


def _parse_entry(line: str) -> QueueEntry:
    job_id, name, account, state, reason, start, nodes, comment = (
        line.split("|", 7) + [""] * 8)[:8]
    return QueueEntry(job_id=job_id, name=name, account=account, state=state, reason=reason,
                      expected_start=start, nodes=nodes, comment=comment)


__all__ = ["HOST_NETNS", "QueueEntry", "SlurmPool"]
