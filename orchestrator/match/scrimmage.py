"""``hlvs scrimmage``: a short match between two teams of stub robots, from generated files.

The files (game.json, team_red.json, team_blue.json) are written into the output folder and then
played exactly like ``hlvs match`` would play them, so a team can rerun or edit them.
Defaults: 1 player per team, two halves of 30 s simulated, lockstep stepping, 3 s before READY.
"""

from __future__ import annotations

import argparse
import json
import uuid
from pathlib import Path
from typing import Any

from orchestrator.commands.scrimmage_args import add_arguments

POSES_KID = {  # as if playing on the left (x < 0)
    1: (-4.0, -3.1, 1.57),
    2: (-1.0, -3.1, 1.57),
    3: (-2.0, -3.1, 1.57),
    4: (-3.0, -3.1, 1.57),
}

# Players 3 and 4 defend from spots in the own half: three strikers chasing one ball mostly
# knock each other over.
DEFENDER_HOMES = {3: (-2.3, 1.0), 4: (-2.3, -1.0)}


def _pose(x: float, y: float, yaw: float) -> dict[str, Any]:
    return {"translation": [x, y, 0.43], "rotation": [0, 0, 1, yaw]}


def team_file(name: str, image: str, players: int, *, goalie_first: bool,
              command: str | None = None) -> dict[str, Any]:
    repository, _, tag = image.rpartition(":") if ":" in image.split("/")[-1] else (image, "", "")
    entries: dict[str, Any] = {}
    for n in range(1, players + 1):
        x, y, yaw = POSES_KID[n]
        role = "goalie" if (n == 1 and goalie_first) else "striker"
        extra = ""
        if n in DEFENDER_HOMES and players >= n:  # one striker; the others keep their spots
            role = "defender"
            extra = " --home {} {}".format(*DEFENDER_HOMES[n])
        entries[str(n)] = {
            # The stub cannot see where it was placed: its dockerCmd tells it (team-file frame).
            "dockerCmd": command or f"{role} --start-pose {x} {y} {yaw}{extra}",
            "halfTimeStartingPose": _pose(x, y, yaw),
            "reentryStartingPose": _pose(x, y, yaw),
            "shootoutStartingPose": _pose(2.6, 0.0, 0.0),
            "goalKeeperStartingPose": _pose(-4.45, 0.0, 0.0),
        }
        if tag:
            entries[str(n)]["dockerTag"] = tag
    return {"name": name, "image": repository or image, "players": entries}


def game_file(args: argparse.Namespace, match_id: str) -> dict[str, Any]:
    players = args.players
    return {
        "type": "NORMAL",
        "class": "KID",
        "host": "127.0.0.1",
        "maximum_real_time_factor": 0,
        "side_left": "red",
        "kickoff": "red",
        "match_id": match_id,
        "seed": args.seed,
        "stepping": "lockstep",
        "lockstep_deadline_ms": 200,
        "lockstep_time_bank_ms": 10000,
        "red": {"id": 1, "config": "team_red.json", "hosts": ["127.0.0.1"],
                "ports": [10000 + n for n in range(1, players + 1)]},
        "blue": {"id": 2, "config": "team_blue.json", "hosts": ["127.0.0.1"],
                 "ports": [10020 + n for n in range(1, players + 1)]},
        "timing": {
            "half_duration_s": args.half_duration,
            "wait_before_first_ready_s": args.wait_before_ready,
            "half_time_break_s": 1,
            "grace_period_s": args.grace,
        },
        "limits": {"cpus": 1, "memory_gb": 1, "pids": 256, "log_folder_gb": 1},
    }


def write_files(args: argparse.Namespace, folder: Path, *, stub_image: str | None = None
                ) -> Path:
    """Write game.json and the two team files into ``folder``; returns the game.json path."""
    if args.red_image is None or args.blue_image is None:
        if stub_image is None:
            from orchestrator.images import project_image

            stub_image = project_image("stub")
    red_image = args.red_image or stub_image
    blue_image = args.blue_image or stub_image
    assert red_image is not None and blue_image is not None
    match_id = args.match_id or f"scrimmage-{uuid.uuid4().hex[:6]}"
    folder.mkdir(parents=True, exist_ok=True)
    files = {
        "game.json": game_file(args, match_id),
        "team_red.json": team_file("Stub Red", red_image, args.players,
                                   goalie_first=args.players > 1, command=args.robot_command),
        "team_blue.json": team_file("Stub Blue", blue_image, args.players, goalie_first=True,
                                    command=args.robot_command),
    }
    for name, content in files.items():
        (folder / name).write_text(json.dumps(content, indent=2) + "\n", encoding="utf-8")
    return folder / "game.json"


__all__ = ["add_arguments", "game_file", "team_file", "write_files"]
