"""``hlvs compose GAME.json -o docker-compose.yml``: the match as a docker-compose project.

Writes the compose file, ``match_spec.json`` next to it, and the ``out/`` and ``logs/`` folders;
``docker compose up --abort-on-container-exit --exit-code-from simulator`` (or the same with
``docker-compose`` 1.27 or later) then plays the match. The same command with ``--collect``
then writes ``results.json`` and ``report.json`` next to the compose file, and
``docker compose down`` removes the containers and networks.
"""

from __future__ import annotations

import argparse
import ipaddress
import json
from typing import TYPE_CHECKING, Any

from orchestrator import ConfigError, Problem, user_path

if TYPE_CHECKING:
    from orchestrator.config import LoadedGame


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "compose", help="write a docker-compose file that plays the match of a game.json"
    )
    parser.add_argument("game", type=user_path, help="game.json (its team files are read too)")
    parser.add_argument(
        "-o", "--output", type=user_path, default="docker-compose.yml",
        help="compose file to write (default: docker-compose.yml)",
    )
    parser.add_argument(
        "--simulator-image",
        metavar="IMAGE",
        help="simulator image (default: the current hlvs-runner/simulator build)",
    )
    parser.add_argument(
        "--subnet-start",
        metavar="A.B.C.0",
        help="first of three consecutive /24 subnets for red, blue and control "
        "(default: in 10.214.0.0/16, derived from the match id)",
    )
    parser.add_argument(
        "--collect", action="store_true",
        help="after the match was played: write results.json and report.json next to the "
        "compose file from out/sim_result.json (exit 0 only when the match played)",
    )
    parser.add_argument(
        "--json", action="store_true",
        help="print one JSON object (files written, warnings, command to play it)",
    )
    parser.set_defaults(func=_compose)


def _compose(args: argparse.Namespace) -> int:
    from orchestrator import Subnets, write_compose
    from orchestrator.config import load_game

    subnets = None
    if args.subnet_start:
        try:
            subnets = Subnets.starting_at(ipaddress.IPv4Network(f"{args.subnet_start}/24"))
        except ValueError as exc:
            raise ConfigError(
                [Problem("(command line)", "--subnet-start", str(exc), "an address like 10.9.0.0")]
            ) from exc
    loaded = load_game(args.game, images_required=True)
    if args.collect:
        return _collect(args, loaded)
    if not args.json:
        for warning in loaded.warnings:
            print(warning)
    if args.simulator_image:
        image = args.simulator_image
    else:
        from orchestrator import project_image

        image = project_image("simulator")
    spec = write_compose(loaded, args.output, simulator_image=image, subnets=subnets)
    up = f"-f {args.output.name} up --abort-on-container-exit --exit-code-from simulator"
    command = f"docker compose {up}"
    collect = f"hlvs compose {args.game} -o {args.output} --collect"
    down = f"-f {args.output.name} down"
    if args.json:
        print(
            json.dumps(
                {
                    "compose_file": str(args.output),
                    "match_spec": str(spec),
                    "warnings": [str(w) for w in loaded.warnings],
                    "directory": str(args.output.parent),
                    "command": command,
                    "command_v1": f"docker-compose {up}",
                    "collect": collect,
                    "down": f"docker compose {down}",
                    "down_v1": f"docker-compose {down}",
                },
                indent=2,
            )
        )
        return 0
    print(f"wrote {args.output} and {spec}")
    print(f"play it: cd {args.output.parent} && {command}")
    print(f"  or, with docker-compose 1.27 or later: docker-compose {up}")
    print(f"then results.json and report.json: {collect}")
    print(f"and remove its containers and networks: docker compose {down}")
    print(f"  or: docker-compose {down}")
    return 0


def _collect(args: argparse.Namespace, loaded: LoadedGame) -> int:
    from orchestrator import ExitCode, collect_results

    results = collect_results(loaded, args.output.parent)
    folder = args.output.parent
    summary = {"results": str(folder / "results.json"), "report": str(folder / "report.json"),
               "status": results.status, "score": results.score,
               "failure": None if results.failure is None else
               f"{results.failure.failure_class.value}: {results.failure.cause}"}
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print(f"wrote {summary['results']} and {summary['report']}: {results.status}"
              + (f" ({summary['failure']})" if results.failure else f", score {results.score}"))
    return int(ExitCode.OK if results.ok else ExitCode.FAILED)
