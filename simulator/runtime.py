"""``python -m simulator run --spec match_spec.json --out DIR``: the simulator process.

Wires the world, the robot API server, the referee (GameController, mirror, AutoRef), the
recorder and telemetry, runs :class:`simulator.match_loop.MatchLoop` and writes into ``--out``:
``sim_result.json``, ``replay.hlvsrec``, ``api_stats.jsonl``, ``referee.log``,
``referee_events.jsonl``, ``gamecontroller.log`` and the video when the spec asks for one. Exit
codes: 0 the game reached FINISHED, 1 it did not (time limit, physics divergence), 2 invalid
spec, 3 infrastructure (a port or the telemetry endpoint unavailable), 130 stopped by SIGTERM /
SIGINT (results still written).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import platform
import signal
import sys
import time
from contextlib import ExitStack
from pathlib import Path
from types import FrameType
from typing import TYPE_CHECKING, Any

from contracts import ContractError, MatchSpec, SimResult, files
from simulator.api import ApiServer, LockstepSettings, endpoints_from_spec
from simulator.errors import (
    GpuRenderError,
    OffscreenGLError,
    PhysicsDivergence,
    SimulatorError,
    UnknownModelError,
)
from simulator.gl import read_gl_info, select_match_gl
from simulator.match_loop import LoopSettings, MatchLoop
from simulator.match_setup import referee_config
from simulator.telemetry import Telemetry, TelemetryError, open_telemetry
from simulator.traffic import STATS_FILE, TrafficLog

if TYPE_CHECKING:
    from referee import Referee
    from simulator.api.cameras import ImageSource
    from simulator.recorder import Recorder
    from simulator.world import World

log = logging.getLogger(__name__)

RESULT_FILE = files.SIM_RESULT
REPLAY_FILE = files.REPLAY


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="python -m simulator run")
    parser.add_argument("--spec", required=True, help="match_spec.json written by the orchestrator")
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--log-level", default="INFO")
    parser.add_argument(
        "--no-gc-network",
        action="store_true",
        help="do not open the GameController UDP ports and the team mirror",
    )
    return parser


def versions() -> dict[str, str]:
    from importlib.metadata import PackageNotFoundError, version

    out = {"python": platform.python_version()}
    for name in ("hlvs-runner", "mujoco", "protobuf", "eclipse-zenoh"):
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


def main(argv: list[str]) -> int:
    args = _parser().parse_args(argv)
    logging.basicConfig(
        level=args.log_level.upper(),
        stream=sys.stderr,
        format="%(asctime)s %(levelname)s %(name)s: %(message)s",
    )
    if not os.environ.get("DISPLAY"):  # offscreen rendering (cameras, video) without a display
        try:  # OSMesa, or EGL on the GPU the orchestrator gave this container (before MuJoCo)
            select_match_gl()
        except GpuRenderError as exc:
            log.error("%s", exc)
            return 3
    # Mesa's CPU rasteriser inline in the rendering thread (no rasteriser threads): camera
    # rendering takes one core, physics keeps another. Measured at 320x240 with 8 cameras in
    # lockstep: 5.2 ms a frame and RTF 0.69, against 6.1 ms and 0.58 with one rasteriser thread.
    os.environ.setdefault("LP_NUM_THREADS", "0")
    try:
        spec = MatchSpec.load(args.spec)
    except ContractError as exc:
        log.error("invalid match spec: %s", exc)
        return 2
    out = Path(args.out)
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        log.error("cannot create the output folder %s: %s", out, exc)
        return 3
    try:
        return run_match(spec, out, gc_network=not args.no_gc_network)
    except UnknownModelError as exc:
        log.error("invalid match spec %s: %s", args.spec, exc)
        return 2
    except TelemetryError as exc:
        log.error("%s", exc)
        return 3
    except OSError as exc:
        log.error("infrastructure failure: %s", exc)
        return 3
    except SimulatorError as exc:
        log.error("%s", exc)
        return 3


def run_match(spec: MatchSpec, out: Path, *, gc_network: bool = True) -> int:
    """Play the match of ``spec``, writing every output file into ``out``; returns the exit code."""
    from referee import Referee
    from simulator.api.world_cameras import render_processes, world_render_worker
    from simulator.world import World

    log.info(
        "match %s: %s %s, seed %d, %s stepping, max real-time factor %g",
        spec.match_id, spec.game_type, spec.field_class, spec.seed, spec.stepping,
        spec.maximum_real_time_factor,
    )  # fmt: skip
    world = World.from_spec(spec)
    lockstep = LockstepSettings(
        deadline_s=spec.lockstep_deadline_ms / 1000.0,
        time_bank_s=spec.lockstep_time_bank_ms / 1000.0,
        pipelined=spec.stepping == "pipelined",
    )
    started = time.time()
    with ExitStack() as stack:
        processes = render_processes()
        cameras = world_render_worker(world, processes=processes)
        stack.callback(cameras.close)
        # ready while the server starts and the robots connect; started before this process
        # makes an OpenGL context or a thread, so that its render processes are forked
        cameras.start()  # says how many processes, forked or spawned
        camera_gl = _camera_gl()
        referee = Referee(config=referee_config(spec), log_dir=out)
        stack.callback(referee.close)
        server = ApiServer(
            world=world,
            endpoints=endpoints_from_spec(spec),
            network=spec.network,
            lockstep=lockstep if spec.stepping in ("lockstep", "pipelined") else None,
            cameras=cameras,
            spoofing=referee.spoofing,
        )
        server.start()
        stack.callback(server.close)
        if gc_network:
            referee.start_network()
        reserve = files.reserve_space(out, log)
        recorder, telemetry, traffic = _open_outputs(spec, out, world, server, stack)
        loop = MatchLoop(
            world=world,
            referee=referee,
            server=server,
            recorder=recorder,
            telemetry=telemetry,
            traffic=traffic,
            settings=LoopSettings(
                stepping=spec.stepping,
                maximum_real_time_factor=spec.maximum_real_time_factor,
                lockstep=lockstep,
                end_of_game_real_s=spec.timing.end_of_game_real_s,
                max_duration_real_s=spec.timing.max_duration_real_s,
            ),
        )
        stack.enter_context(_stop_on_signals(loop))
        reason, error = _play(loop)
        recorder.close(world)
        exit_code = _EXIT_CODES.get(reason, 1)
        result = _result(
            spec, out, world=world, referee=referee, loop=loop, server=server, reason=reason,
            error=error, cameras=cameras, processes=processes, camera_gl=camera_gl,
            started=started,
        )  # fmt: skip
    reserve.unlink(missing_ok=True)  # its space is the results' on a disk that filled
    result.write(out / RESULT_FILE)
    log.info(
        "match %s ended (%s): %s, score %s, %d ms simulated in %.1f s",
        spec.match_id, reason, result.state, result.score, world.sim_time_ms,
        loop.real_time_s,
    )  # fmt: skip
    if spec.record_video:
        _render_video(out / REPLAY_FILE, out / spec.record_video)
    return exit_code


_EXIT_CODES = {"finished": 0, "SIGTERM": 130, "SIGINT": 130}
"""The process's exit code by the loop's stop reason; any other reason: 1."""


def _open_outputs(
    spec: MatchSpec, out: Path, world: World, server: ApiServer, stack: ExitStack
) -> tuple[Recorder, Telemetry, TrafficLog]:
    """The replay recorder (closed by the caller with the world's last state), the telemetry
    stream and the API traffic log (both closed by ``stack``)."""
    from simulator.recorder import Recorder, replay_header

    recorder = Recorder(
        out / REPLAY_FILE, world, match_id=spec.match_id, rate_hz=spec.recorder_rate_hz
    )
    telemetry = open_telemetry(
        match_id=spec.match_id,
        listen=spec.network.telemetry_listen,
        scene=replay_header(
            world, match_id=spec.match_id, rate_hz=spec.recorder_rate_hz, chunk_frames=1
        ),
    )
    stack.callback(telemetry.close)
    traffic = TrafficLog(server, path=out / STATS_FILE)
    stack.callback(traffic.close)
    return recorder, telemetry, traffic


def _play(loop: MatchLoop) -> tuple[str, str]:
    """Run the loop; its stop reason and the error that stopped it (empty when none)."""
    try:
        return loop.run(), ""
    except PhysicsDivergence as exc:
        log.error("%s", exc)
        return "physics_divergence", str(exc)
    except Exception as exc:  # process boundary: the results still record the state reached
        log.exception("match loop failed")
        return "internal_error", f"{type(exc).__name__}: {exc}"


def _result(
    spec: MatchSpec,
    out: Path,
    *,
    world: World,
    referee: Referee,
    loop: MatchLoop,
    server: ApiServer,
    reason: str,
    error: str,
    cameras: ImageSource,
    processes: int,
    camera_gl: dict[str, str],
    started: float,
) -> SimResult:
    """The match's ``sim_result.json``: the referee's result, why and when the loop stopped,
    its timing, the robots' API statistics, the cameras' figures and the versions."""
    fields: dict[str, Any] = {
        "match_id": spec.match_id,
        "seed": spec.seed,
        **referee.result(),
        "stop_reason": reason,
        "error": error,
        "stepping": spec.stepping,
        "sim_time_ms": world.sim_time_ms,
        "real_time_s": round(loop.real_time_s, 3),
        "held_real_s": round(loop.held_s, 3),
        "real_time_factor": _rtf(world.sim_time_ms, loop.real_time_s - loop.held_s),
        "robots": server.statistics(),
        "cameras": {"frames": cameras.frames, "render_s": round(cameras.render_s, 3),
                    "render_processes": processes, **camera_gl},
        "started_unix_s": round(started, 3),
        "versions": versions(),
    }  # fmt: skip
    return SimResult.from_dict(
        json.loads(json.dumps(fields, default=str)), source=str(out / RESULT_FILE)
    )


def _camera_gl() -> dict[str, str]:
    """The OpenGL the robot cameras render with (logged; the ``gl_*`` keys of the result's
    ``cameras``): ``gl_backend`` and ``gl_renderer`` (llvmpipe: the CPU), or ``gl_error``."""
    try:
        info = read_gl_info()
    except OffscreenGLError as exc:
        log.warning("robot cameras: no offscreen OpenGL (%s); camera requests will fail", exc)
        return {"gl_backend": os.environ.get("MUJOCO_GL", ""), "gl_error": str(exc)}
    log.info("robot cameras render with %s", info.describe())
    return info.record()


def _rtf(sim_ms: int, real_s: float) -> float:
    return round(sim_ms / 1000.0 / real_s, 3) if real_s > 0 else 0.0


def _render_video(replay: Path, output: Path) -> None:
    import mujoco

    from simulator.render import render_video

    started = time.monotonic()
    try:
        render_video(replay, output)
    except (OSError, SimulatorError, mujoco.FatalError) as exc:
        log.error("video %s not rendered: %s", output, exc)
        return
    log.info("video %s rendered in %.1f s", output, time.monotonic() - started)


class _stop_on_signals:  # noqa: N801 (used like a context-manager function)
    """SIGTERM / SIGINT ask the loop to stop cleanly; the previous handlers come back after."""

    def __init__(self, loop: MatchLoop) -> None:
        self._loop = loop
        self._previous: dict[int, Any] = {}

    def _handle(self, signum: int, _frame: FrameType | None) -> None:
        name = signal.Signals(signum).name
        log.warning("%s received: stopping the match and writing the results", name)
        self._loop.request_stop(name)

    def __enter__(self) -> _stop_on_signals:
        for signum in (signal.SIGTERM, signal.SIGINT):
            self._previous[signum] = signal.signal(signum, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        for signum, handler in self._previous.items():
            signal.signal(signum, handler)
