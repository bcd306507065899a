"""Names of the files (and environment variables) the processes hand to each other, spelled
once.

The orchestrator mounts a match folder into the simulator container at ``/match``: it writes
:data:`MATCH_SPEC` there, the simulator writes everything else into :data:`OUT_DIR`; the public
files are copied next to the orchestrator's :data:`RESULTS` and :data:`REPORT`.
"""

from __future__ import annotations

import logging
from pathlib import Path

CONTAINER_MATCH_DIR = "/match"  # the match folder inside the simulator container
MATCH_SPEC = "match_spec.json"  # contracts.match_spec.MatchSpec
OUT_DIR = "out"  # the simulator's output folder, inside the match folder
SIM_RESULT = "sim_result.json"  # contracts.sim_result.SimResult
REPLAY = "replay.hlvsrec"
API_STATS = "api_stats.jsonl"
REFEREE_LOG = "referee.log"
REFEREE_EVENTS = "referee_events.jsonl"
GAMECONTROLLER_LOG = "gamecontroller.log"
VIDEO = "match.mp4"
RESULTS = "results.json"  # the orchestrator's match results
REPORT = "report.json"  # written last: the match folder is complete
# environment of the simulator container: the gpu setting (on | auto) when the orchestrator gave
# it the host's NVIDIA GPU
GPU_ENVIRONMENT = "HLVS_GPU"
# space the simulator (in its output folder) and the orchestrator (in the match folder) set aside
# at the start and give back just before writing their results, so that a disk that fills during
# the match still takes the outcome
RESERVE_FILE = ".results-reserve"
RESERVE_BYTES = 1 << 20

PUBLIC_FILES = (
    SIM_RESULT, REPLAY, API_STATS, REFEREE_LOG, REFEREE_EVENTS, GAMECONTROLLER_LOG, VIDEO,
)  # fmt: skip
"""Simulator outputs published with the match (the logs teams and spectators may read)."""

def reserve_space(out: Path, log: logging.Logger) -> Path:
    """A file of :data:`RESERVE_BYTES` in ``out`` (written, so that its blocks are allocated);
    a disk already too full for it gets none, said in ``log``. Its path."""
    path = out / RESERVE_FILE
    try:
        with path.open("wb") as handle:
            handle.write(b"\0" * RESERVE_BYTES)
    except OSError as exc:
        log.warning("no space reserved for the results in %s: %s", out, exc.strerror or exc)
        path.unlink(missing_ok=True)
    return path


__all__ = [
    "API_STATS",
    "CONTAINER_MATCH_DIR",
    "GAMECONTROLLER_LOG",
    "GPU_ENVIRONMENT",
    "MATCH_SPEC",
    "OUT_DIR",
    "PUBLIC_FILES",
    "REFEREE_EVENTS",
    "REFEREE_LOG",
    "REPLAY",
    "REPORT",
    "RESERVE_BYTES",
    "RESERVE_FILE",
    "RESULTS",
    "SIM_RESULT",
    "VIDEO",
    "reserve_space",
]
