"""``hlvs match``, ``hlvs scrimmage`` and ``hlvs cleanup`` at work: wire the real engine, host
controls, image resolution and telemetry to :class:`orchestrator.match.MatchRunner`.

Exit codes: 0 the match played to its end, 1 it failed (see report.json), 2 invalid input,
3 infrastructure, 4 decided by forfeit, 130 interrupted (SIGINT / SIGTERM: everything is stopped
and collected first).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, TextIO

from hlvs.commands.outcome import summarize
from orchestrator import (
    ConfigError,
    ExitCode,
    OrchestratorError,
    Problem,
    local_name_reason,
    stop_on_signals,
    user_path,
)
from orchestrator.config import load_game
from orchestrator.engine import LABEL_SLURM_JOB
from orchestrator.match import (
    LABEL_RUN,
    GpuOrigin,
    HostControl,
    HostResources,
    ImageResolver,
    LeaguePlacement,
    MatchOutcome,
    MatchPlan,
    MatchRunner,
    RegistryAccess,
    RunOptions,
    SimulatorGpu,
    admit,
    check_robot_runtime,
    clean_match,
    cleanup,
    local_images,
    ownership,
    parse_nodes,
    plan_from_game,
    scrimmage,
    simulator_gpu,
    start_gate,
)

if TYPE_CHECKING:
    from docker import DockerClient

    from orchestrator.engine import DockerRuntime

log = logging.getLogger(__name__)


def _pull_resolver(client: DockerClient, registry: RegistryAccess) -> ImageResolver:
    from orchestrator import resolve_team_images

    def resolve(plan: MatchPlan) -> dict[str, tuple[str | None, str | None]]:
        from orchestrator import progress

        found: dict[str, tuple[str | None, str | None]] = {}
        for color in ("red", "blue"):
            with progress(allow_rich=False) as bars:  # under the match's live view
                resolved = resolve_team_images(
                    client, registry.team(color), limits=plan.limits, progress=bars,
                    registry_only=registry.registry_only,
                )
            for number, image in resolved.items():
                key = f"{color}-{number}"
                found[key] = (image.digest or None, str(image.error) if image.error else None)
        for robot in plan.robots:
            found.setdefault(robot.key, (None, "no image named for this player"))
        return found

    return resolve


def play(
    plan: MatchPlan, *, out_dir: Path, pull: bool,
    extra_labels: dict[str, str] | None = None, view_stream: TextIO | None = None,
    placement: LeaguePlacement | None = None,
) -> MatchOutcome:
    """Play ``plan`` on the local engine with the real host controls, showing progress. The
    match id is claimed first (:class:`~orchestrator.match.ownership.MatchRunning` while another
    orchestrator plays it); what a dead earlier run of it left is salvaged and removed. An
    official match that does not fit the host is refused before all that
    (:mod:`orchestrator.match.admission`), and so is a match whose ``limits.robot_runtime``
    the engine does not have (:mod:`orchestrator.match.robot_runtime`). ``pull``: the team
    images are pulled from the plan's registries (:attr:`MatchPlan.registry`)."""
    from orchestrator.engine import (
        DockerRuntime,
        connect,
        detect_nvidia,
        engine_endpoint,
        engine_runtimes,
    )

    verdict = admit(plan, host=HostResources.local(), official=plan.official)
    plan = replace(plan, admission=verdict.record())
    client = connect()
    check_robot_runtime(plan, engine=engine_endpoint(), runtimes=lambda: engine_runtimes(client))
    gpu = simulator_gpu(plan.gpu, lambda: detect_nvidia(client), origin=plan.gpu_origin)
    runtime = DockerRuntime(client)
    host = HostControl.for_current_user()
    with ownership.claim(plan.match_id, out_dir) as claim:  # refused while another runs it
        leftovers = clean_match(runtime, host, match_id=plan.match_id, record=claim.previous,
                                keep_run=claim.record.run_id)
        if leftovers.containers or leftovers.networks:
            log.info("removed %d containers and %d networks left by an earlier run of %s",
                     len(leftovers.containers), len(leftovers.networks), plan.match_id)
        labels = {**(extra_labels or {}), LABEL_RUN: claim.record.run_id}
        if os.environ.get("SLURM_JOB_ID", "").isdigit():  # the cluster's epilog removes them
            labels[LABEL_SLURM_JOB] = os.environ["SLURM_JOB_ID"]
        return _play(plan, out_dir=out_dir, pull=pull, client=client,
                     runtime=runtime, host=host, extra_labels=labels, view_stream=view_stream,
                     placement=placement, gpu=gpu)


def _play(
    plan: MatchPlan, *, out_dir: Path, pull: bool, client: DockerClient, runtime: DockerRuntime,
    host: HostControl, extra_labels: dict[str, str], view_stream: TextIO | None = None,
    placement: LeaguePlacement | None = None, gpu: SimulatorGpu | None = None,
) -> MatchOutcome:
    from orchestrator import LiveView, ZenohTelemetry, project_image

    simulator_image = project_image("simulator")
    registry = plan.registry
    images = _pull_resolver(client, registry) if pull and registry is not None else None
    view = LiveView(match_id=plan.match_id, stream=view_stream)
    with stop_on_signals() as stop_event:
        options = RunOptions(
            out_dir=out_dir, simulator_image=simulator_image, extra_labels=extra_labels or {},
            progress=lambda phase, state: view.update(phase=phase, state=state),
            placement=placement, gpu=gpu,
            start_gate=start_gate() if placement is None else None,
        )
        runner = MatchRunner(
            plan, runtime=runtime, host=host, options=options,
            images=images or local_images(runtime),
            telemetry=lambda endpoint, match_id: ZenohTelemetry(
                endpoint=endpoint, match_id=match_id),
            stop_event=stop_event,
        )
        try:
            outcome = runner.run()
        finally:
            view.close()
    return outcome


def run_match_command(args: argparse.Namespace) -> int:
    loaded = load_game(args.game, images_required=True)
    for warning in loaded.warnings:
        print(f"hlvs: {warning}", file=sys.stderr)
    plan = _gpu_option(args, plan_from_game(loaded, grace_period_s=args.grace))
    out = args.out or user_path(Path("matches") / plan.match_id)
    if getattr(args, "pool", "local") == "slurm":
        return _in_pool(args, game_path=args.game, plan=plan, out=out)
    outcome = play(plan, out_dir=out, pull=True,
                   view_stream=sys.stderr if getattr(args, "json", False) else None,
                   placement=_placement(args, plan))
    return summarize(outcome, as_json=getattr(args, "json", False))


def run_scrimmage_command(args: argparse.Namespace) -> int:
    out: Path = args.out
    for image in (args.red_image, args.blue_image):
        if image and local_name_reason(image) is not None:
            log.warning("scrimmage: %s is played as this host has it (for the operator's own "
                        "use; league and service matches take team images only from a "
                        "registry)", image)
    game_path = scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args),
                                       out / "config")
    loaded = load_game(game_path, images_required=True)
    plan = _gpu_option(args, plan_from_game(loaded, grace_period_s=args.grace))
    if getattr(args, "pool", "local") == "slurm":
        return _in_pool(args, game_path=game_path, plan=plan, out=out)
    outcome = play(plan, out_dir=out, pull=False,
                   view_stream=sys.stderr if getattr(args, "json", False) else None,
                   placement=_placement(args, plan))
    return summarize(outcome, as_json=getattr(args, "json", False))


def _gpu_option(args: argparse.Namespace, plan: MatchPlan) -> MatchPlan:
    """``--gpu`` given on the command line overrides ``gpu`` of game.json."""
    mode = getattr(args, "gpu", None)
    if mode is None:
        return plan
    return replace(plan, gpu=mode, gpu_origin=GpuOrigin(file="command line", pointer="--gpu"))


def _placement(args: argparse.Namespace, plan: MatchPlan) -> LeaguePlacement | None:
    """League placement inside its Slurm job (``--league-nodes``); None: dense."""
    if getattr(args, "placement", "dense") != "league":
        return None
    if not getattr(args, "league_nodes", None):
        raise ConfigError([Problem(
            file="command line", pointer="--placement",
            message="league placement needs its nodes",
            expected="--pool slurm (the cluster allocates a node per robot), or "
            "--league-nodes NAME=ADDR,... inside the job")])
    return parse_nodes(args.league_nodes, [r.key for r in plan.robots],
                       netns=getattr(args, "node_netns", None))


def _in_pool(args: argparse.Namespace, *, game_path: Path, plan: MatchPlan, out: Path) -> int:
    from hlvs.commands.pooled import play_in_pool

    extra = () if args.grace is None else ("--grace", str(args.grace))
    if getattr(args, "gpu", None) is not None:
        extra += ("--gpu", args.gpu)
    league = getattr(args, "placement", "dense") == "league"
    return play_in_pool(args, game_path=game_path, match_id=plan.match_id, out_dir=out,
                        official=plan.official, match_args=extra,
                        robot_nodes=len(plan.robots) if league else 0)


def run_cleanup_command(args: argparse.Namespace) -> int:
    from orchestrator.engine import DockerRuntime, connect

    runtime = DockerRuntime(connect())
    if getattr(args, "dry_run", False):
        from orchestrator.match import plan_cleanup

        planned = plan_cleanup(runtime, match_id=args.match)
        print(json.dumps({
            "dry_run": True, "containers": list(planned.containers),
            "networks": list(planned.networks), "log_mounts": list(planned.mounts),
            "salvaged": list(planned.salvaged), "skipped": list(planned.skipped),
        }))
        return ExitCode.OK
    host = HostControl.for_current_user()
    report = cleanup(runtime, host, match_id=args.match)
    print(json.dumps({
        "containers": list(report.containers), "networks": list(report.networks),
        "host_objects": report.host_objects, "errors": list(report.errors),
        "salvaged": list(report.salvaged), "skipped": list(report.skipped),
    }))
    if report.errors:
        raise OrchestratorError("cleanup incomplete: " + "; ".join(report.errors))
    return ExitCode.OK


__all__ = ["play", "run_cleanup_command", "run_match_command", "run_scrimmage_command"]
