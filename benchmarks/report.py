"""``hlvs bench report``: the performance matrix in one run, every ratio in one JSON document.

Runs, ``--repeats`` times and interleaved (so that the load of other processes falls on every
kind alike), each benchmark as a child process with small sizes:

- ``sim``: ``bench sim`` (the world against a bare ``mj_step`` loop), ratio and CPU ratio,
  ``--world-seconds`` long;
- ``async``, ``lockstep``, ``pipelined``: ``bench api --mode M`` with ``--robots`` clients;
  the target figure is ``ratio_interleaved``: the API run's speed over the world's alone
  (``World.step`` + snapshot, what ``bench sim`` times) measured in alternating chunks of the
  same run, so that a change of load between the two does not show as a ratio; also the ratio
  to a ``bench sim`` run and to a world-only run before it, the CPU ratios and the share of
  time the step waited for its clients;
- ``lockstep_league``: ``bench api --mode lockstep --client league``: the same figures with
  clients written like the league's own (each request's length and body in two writes, no
  ``TCP_NODELAY``: :mod:`testkit.league_client`), and their requests per second and round
  trips; judged against the lockstep target;
- every ``bench api`` kind runs compiled clients (``bench api --native``) when the machine
  has a C compiler (``native_clients`` says which ran: the clients share the bench machine's
  CPUs with the server they measure), and the lockstep kinds give with them the serial floor
  of lockstep on this machine (``floor_ratio``: a C server stepping a busy loop as long as the
  world's step with the same clients; ``of_floor``: the API run's ratio over it);
- each ``bench api`` kind without cameras gives ``neighbour_ratio``: the world's step with the
  clients' CPU busy over idle, timed before the run (:mod:`testkit.neighbour`): about 1,
  unless the machine's two virtual CPUs share a physical core at the time, which slows the
  step thread whenever the clients' CPU is busy (pipelined stepping most); ``shared_core_runs``
  counts the kind's runs timed so (ratio 1.15 or more);
- ``cameras``: ``bench api --mode async`` with every robot's camera at 320x240 every 32 ms,
  rendered as a match renders them (``render_processes``: worker processes on the CPU
  renderer, one per CPU; 0: one thread) (the real-time factor is the figure: rendering is most
  of the cost);
- ``bringup``: ``bench bringup`` (a real match of stub robots in Docker, images cached), in
  ``--bringup-repeats`` of the runs (default all: one bring-up is Docker starting 17 containers
  and spreads by a second on a small host); needs Docker and the project's images;
- ``match``: a whole match, in ``--match-repeats`` of the runs (default 1: minutes each): 4 v 4
  stub robots in Docker, each with its 320x240 camera, ``async`` stepping uncapped, halves of
  ``--match-half-duration`` simulated seconds (``hlvs match`` of a scrimmage's files, as ``bench
  hog``); its simulator's real-time factor, the wall seconds per simulated minute, the wall
  seconds outside the game, and from them what a match of the league's length and timing
  (two 10 min halves, 45 s READYs, the referee's wall waits, paced to real time at most) takes
  on this machine and how many such matches a core-hour plays
  (:func:`testkit.figures.league_match_figures`); no target. Needs Docker and the images.

Prints one JSON document: per kind its runs, the median of each figure, the target and whether
the median meets it; the load average before and after, so that a figure is read with the load
it was measured under, and the share of the CPUs' time the hypervisor gave to other machines
(``steal_share``, from ``/proc/stat``: over the whole report and for each run; on a virtual
machine with busy neighbours a run can lose a tenth of its CPU this way). A benchmark that
fails is reported with its error (exit code 1).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from benchmarks import native_clients
from contracts import files
from testkit import neighbour
from testkit.figures import (
    MACHINE_SCALED,
    REFERENCE_BARE_REAL_TIME_FACTOR,
    cpu_times,
    league_match_figures,
    machine_target,
    median_figures,
    report_rounds,
    steal_share,
)

KINDS = ("sim", "async", "lockstep", "lockstep_league", "pipelined", "cameras", "bringup",
         "match")




def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="hlvs bench report", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--robots", type=int, default=8, help="robots / clients (default 8)")
    parser.add_argument("--repeats", type=int, default=3,
                        help="runs of each kind, interleaved; medians over them (default 3)")
    parser.add_argument("--sim-seconds", type=float, default=2.0,
                        help="simulated seconds per API run (default 2)")
    parser.add_argument("--world-seconds", type=float, default=6.0,
                        help="simulated seconds per sim run (default 6: the world alone runs "
                             "fast, and its ratio to the bare loop needs a longer run to settle: "
                             "2 s runs spread 0.88-1.05 where 8 s runs gave 0.96-1.0)")
    parser.add_argument("--camera-seconds", type=float, default=1.0,
                        help="simulated seconds per camera run (default 1)")
    parser.add_argument("--bringup-repeats", type=int, default=None,
                        help="bring-up runs (real matches in Docker, about 10 s each; default "
                             "--repeats)")
    parser.add_argument("--match-repeats", type=int, default=1,
                        help="whole-match runs (4 v 4 in Docker, minutes each; default 1)")
    parser.add_argument("--match-half-duration", type=float, default=10.0,
                        help="simulated seconds per half of the whole match (default 10)")
    parser.add_argument("--only", default=",".join(KINDS),
                        help=f"comma-separated kinds to run (default all: {','.join(KINDS)})")
    parser.add_argument("--json", action="store_true", help="print only the JSON document")
    return parser


def _child(argv: list[str], timeout_s: float) -> dict[str, Any]:
    """Run one benchmark child; its last stdout line is its JSON (or an error entry)."""
    env = dict(os.environ, HLVS_PROG="hlvs")
    try:
        proc = subprocess.run([sys.executable, *argv], capture_output=True, text=True,
                              timeout=timeout_s, env=env)  # fmt: skip
    except subprocess.TimeoutExpired:
        return {"error": f"no result within {timeout_s:.0f} s"}
    lines = proc.stdout.strip().splitlines()
    try:
        result: dict[str, Any] = json.loads(lines[-1]) if lines else {}
    except json.JSONDecodeError:
        result = {}
    if proc.returncode != 0 or not result or "error" in result:
        last = (proc.stderr.strip().splitlines() or ["(no output)"])[-1]
        return {"error": result.get("error") or f"exit code {proc.returncode}: {last}"}
    return result


def _api_figures(result: dict[str, Any]) -> dict[str, Any]:
    bench_sim = (result.get("bench_sim") or {}).get("real_time_factor")
    rtf = result["real_time_factor"]
    return {
        "real_time_factor": rtf,
        "bench_sim_real_time_factor": bench_sim,
        "ratio_to_bench_sim": round(rtf / bench_sim, 3) if bench_sim else None,
        "ratio_to_world_only": result["ratio"],
        "ratio_interleaved": result.get("ratio_interleaved"),
        "cpu_ratio": result["cpu_ratio"],
        "cpu_ratio_interleaved": result.get("cpu_ratio_interleaved"),
        "client_wait_share": result.get("client_wait_share"),
        "round_trip_p50_ms": result.get("round_trip_p50_ms"),
        "slow_periods": result.get("slow_periods"),
        "native_clients": result.get("native_clients"),
        "floor_ratio": (result.get("lockstep_floor") or {}).get("ratio"),
        "of_floor": (result.get("lockstep_floor") or {}).get("of_floor"),
        "neighbour_ratio": (result.get("neighbour_cost") or {}).get("ratio"),
    }


def _runners(args: argparse.Namespace) -> dict[str, Callable[[], dict[str, Any]]]:
    robots = str(args.robots)
    sim_s = str(args.sim_seconds)
    api = ["-m", "benchmarks", "api", "--robots", robots, "--json"]

    # the clients compiled when a C compiler is here (their own cost on the bench machine's
    # CPUs holds the server back): see benchmarks.native_clients
    if native_clients.compiler():
        api.append("--native")

    def api_mode(mode: str) -> Callable[[], dict[str, Any]]:
        def run() -> dict[str, Any]:
            result = _child([*api, "--mode", mode, "--sim-seconds", sim_s], 600)
            return result if "error" in result else _api_figures(result)

        return run

    def lockstep_league() -> dict[str, Any]:
        result = _child([*api, "--mode", "lockstep", "--client", "league",
                         "--sim-seconds", sim_s], 600)  # fmt: skip
        if "error" in result:
            return result
        league = result.get("league_client") or {}
        figures = _api_figures(result)
        for key in ("requests_per_s", "client_answer_p50_ms", "client_round_trip_p50_ms"):
            figures[key] = league.get(key)
        return figures

    def sim() -> dict[str, Any]:
        result = _child(["-m", "benchmarks", "sim", "--robots", robots,
                         "--sim-seconds", str(args.world_seconds), "--json"], 600)  # fmt: skip
        if "error" in result:
            return result
        keys = ("ratio", "cpu_ratio", "ratio_pair_median", "real_time_factor",
                "bare_real_time_factor")
        return {k: result[k] for k in keys if k in result}

    def cameras() -> dict[str, Any]:
        result = _child([*api, "--mode", "async", "--camera", "320x240@32",
                         "--sim-seconds", str(args.camera_seconds)], 900)  # fmt: skip
        if "error" in result:
            return result
        return {
            "real_time_factor": result["real_time_factor"],
            "ratio_to_world_only": result["ratio"],
            "camera_frames": result["camera_frames"],
            "render_ms_per_frame": result["render_ms_per_frame"],
            "bare_render_ms_per_frame": result["bare_render_ms_per_frame"],
            "camera_path_ms_per_frame": result["camera_path_ms_per_frame"],
            "render_cost_ratio": result["render_cost_ratio"],
            # what rendered: osmesa / llvmpipe is the CPU; egl with a GPU's name is the GPU
            "gl_backend": result.get("gl_backend"),
            "gl_renderer": result.get("gl_renderer"),
            "render_processes": result.get("render_processes"),  # 0: one render thread
            "native_clients": result.get("native_clients"),
        }

    def bringup() -> dict[str, Any]:
        result = _child(["-m", "hlvs", "bench", "bringup", "--robots", robots,
                         "--json"], 600)  # fmt: skip
        if "error" in result:
            return result
        figures: dict[str, Any] = {}
        for key, value in result.items():
            if isinstance(value, dict):  # phases_s, robot_steps_max_s: one figure each
                figures.update({f"{key}.{name}": v for name, v in value.items()})
            elif key not in ("bench", "robots", "target_s", "ok"):
                figures[key] = value
        return figures

    def match() -> dict[str, Any]:
        return _whole_match(args.match_half_duration)

    return {
        "sim": sim,
        "async": api_mode("async"),
        "lockstep": api_mode("lockstep"),
        "lockstep_league": lockstep_league,
        "pipelined": api_mode("pipelined"),
        "cameras": cameras,
        "bringup": bringup,
        "match": match,
    }


def _whole_match(half_s: float) -> dict[str, Any]:
    """The ``match`` kind: one 4 v 4 stub match in Docker (cameras 320x240), async uncapped."""
    from benchmarks.short_match import play, scrimmage_files

    match_id = f"bench-report-match-{os.getpid()}-{time.monotonic_ns() % 10**6}"
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-match-") as tmp:
        game = scrimmage_files(Path(tmp) / "config", match_id=match_id, half_s=half_s,
                               stepping="async", max_rtf=0.0, options=("--players", "4"))
        started = time.monotonic()
        try:
            results = play("report", game, Path(tmp) / "match", match_id=match_id)
        except SystemExit as exc:  # the match failed: its reason, as the other kinds' errors
            return {"error": str(exc)}
        wall = time.monotonic() - started
        sim_results = sorted((Path(tmp) / "match").rglob(files.SIM_RESULT))
        cameras = json.loads(sim_results[0].read_text()).get("cameras") or {} if sim_results else {}
    rtf = results.real_time_factor or 0.0
    if rtf <= 0 or not results.sim_time_ms:
        return {"error": f"match {match_id}: no real-time factor in its results"}
    phases = dict(results.timings_s)
    outside = sum(phases.values()) - phases.get("playing", 0.0)
    cpus = len(os.sched_getaffinity(0))
    return {
        "real_time_factor": rtf,
        "sim_s": round(results.sim_time_ms / 1000.0, 1),
        "wall_s": round(wall, 1),
        "outside_play_s": round(outside, 1),
        "bringup_s": None if results.bringup_s is None else round(results.bringup_s, 2),
        "camera_frames": cameras.get("frames"),
        "render_processes": cameras.get("render_processes"),
        "gl_renderer": cameras.get("gl_renderer"),
        **league_match_figures(rtf, outside, cpus),
    }


def _load() -> list[float]:
    return [round(x, 2) for x in os.getloadavg()]


def _cpu_times() -> tuple[int, int] | None:
    """(stolen, total) CPU ticks of this machine so far (Linux), or None."""
    try:
        return cpu_times(Path("/proc/stat").read_text())
    except OSError:
        return None


def _kinds(text: str) -> list[str]:
    return [k.strip() for k in text.split(",") if k.strip()]


def _bringup_repeats(args: argparse.Namespace) -> int:
    repeats: int = args.repeats if args.bringup_repeats is None else args.bringup_repeats
    return repeats


def run(args: argparse.Namespace, progress: Callable[[str], None]) -> dict[str, Any]:
    kinds = _kinds(args.only)
    runners = _runners(args)
    runs: dict[str, list[dict[str, Any]]] = {k: [] for k in kinds}
    started = time.monotonic()
    load_before = _load()
    ticks_before = _cpu_times()
    wanted = {kind: args.repeats for kind in kinds}
    wanted.update(bringup=_bringup_repeats(args), match=args.match_repeats)
    for repeat, kinds_now in enumerate(report_rounds(kinds, wanted)):
        for kind in kinds_now:
            progress(f"{kind} run {repeat + 1} (load {_load()[0]})")
            ticks = _cpu_times()
            result = runners[kind]()
            result["load_1min"] = _load()[0]
            result["steal_share"] = steal_share(ticks, _cpu_times())
            note = neighbour.shared_core_note(result.get("neighbour_ratio"))
            if note:
                progress(f"  {note}")
            runs[kind].append(result)
    report: dict[str, Any] = {
        "bench": "report",
        "robots": args.robots,
        "repeats": args.repeats,
        "bringup_repeats": _bringup_repeats(args),
        "match_repeats": args.match_repeats,
        "sim_seconds": args.sim_seconds,
        "world_seconds": args.world_seconds,
        "cpus": len(os.sched_getaffinity(0)),
        "load_average_before": load_before,
        "load_average_after": _load(),
        # the CPU time the hypervisor gave to other machines meanwhile: a figure measured
        # while it was high is the neighbours' as much as ours
        "steal_share": steal_share(ticks_before, _cpu_times()),
        "wall_s": round(time.monotonic() - started, 1),
        "errors": 0,
    }
    medians = {kind: median_figures(runs[kind]) for kind in kinds}
    bare = medians.get("sim", {}).get("bare_real_time_factor")
    report["bare_real_time_factor"] = bare
    report["reference_bare_real_time_factor"] = REFERENCE_BARE_REAL_TIME_FACTOR
    for kind in kinds:
        median = medians[kind]
        entry: dict[str, Any] = {"median": median, "runs": runs[kind]}
        neighbours = [r.get("neighbour_ratio") for r in runs[kind] if "neighbour_ratio" in r]
        if neighbours:  # runs timed while the step thread's CPU shared a core with the clients'
            entry["shared_core_runs"] = neighbour.shared_core_runs(neighbours)
        errors = sum(1 for r in runs[kind] if "error" in r)
        report["errors"] += errors
        target = machine_target(kind, bare)
        if target is not None:
            entry["target"] = target.to_dict()
            if kind in MACHINE_SCALED:
                # None: the sim kind did not run, so the reference machine's bound applies
                entry["target"]["scaled_by_bare_loop"] = bare
            value = median.get(target.figure)
            entry["meets_target"] = None if value is None else target.met(value)
        report[kind] = entry
    return report


def main(argv: Sequence[str]) -> int:
    parser = _parser()
    args = parser.parse_args(list(argv))
    unknown = [k for k in _kinds(args.only) if k not in KINDS]
    if unknown or not _kinds(args.only):
        parser.error(f"--only: unknown kind(s) {', '.join(unknown) or '(none given)'}; "
                     f"expected some of {', '.join(KINDS)}")

    def progress(text: str) -> None:
        print(text, file=sys.stderr, flush=True)  # minutes of work: say where it is

    report = run(args, progress)
    print(json.dumps(report, sort_keys=True, indent=None if args.json else 2), flush=True)
    return 1 if report["errors"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
