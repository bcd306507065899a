"""`hlvs logs`: deliver the pending match logs, show what waits, queue a finished match.

    hlvs logs deliver [--store DIR] [--team NAME] [--json]
    hlvs logs status  [--store DIR] [--json]
    hlvs logs enqueue MATCH_DIR --game GAME.json [--match-id ID] [--store DIR] [--copy]

The store defaults to ``$HLVS_LOG_STORE`` or ``./log-store``. ``deliver`` exits 1 when a set
could not be delivered (it stays in the store with its cause).
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import time
from pathlib import Path
from typing import TYPE_CHECKING, Any

from orchestrator import ConfigError, ExitCode, Problem, user_path

if TYPE_CHECKING:
    from orchestrator.delivery import DeliveryOutcome, PendingSet

STORE_ENV = "HLVS_LOG_STORE"


def default_store() -> Path:
    return user_path(os.environ.get(STORE_ENV, "log-store"))


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "logs", help="match logs: deliver them to the teams' SFTP/S3 targets (deliver, "
        "status, enqueue); a team downloads a test match's from the service (logs fetch)"
    )
    actions = parser.add_subparsers(dest="logs_command", metavar="ACTION")
    actions.required = True

    deliver = actions.add_parser("deliver", help="upload every pending log set")
    _store_option(deliver)
    deliver.add_argument("--team", help="only the sets of this team (or 'public')")
    deliver.add_argument("--json", action="store_true", help="one JSON object per set")
    deliver.set_defaults(func=_deliver)

    status = actions.add_parser("status", help="list the log sets waiting for delivery")
    _store_option(status)
    status.add_argument("--json", action="store_true", help="a JSON array")
    status.set_defaults(func=_status)

    enqueue = actions.add_parser("enqueue", help="queue the logs of a finished match")
    enqueue.add_argument(
        "match_dir", type=user_path, metavar="MATCH_DIR", help="output folder of a finished match"
    )
    enqueue.add_argument(
        "--game",
        type=user_path,
        required=True,
        metavar="GAME.json",
        help="the match's game.json (team names and credentials)",
    )
    enqueue.add_argument("--match-id", help="match id (default: the match id of game.json)")
    enqueue.add_argument("--json", action="store_true", help="a JSON array of the queued sets")
    enqueue.add_argument(
        "--copy",
        action="store_true",
        help="link/copy the team logs instead of moving them into the store",
    )
    _store_option(enqueue)
    enqueue.set_defaults(func=_enqueue)


def _store_option(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "--store",
        type=user_path,
        default=None,
        metavar="DIR",
        help=f"the pending log store (default ${STORE_ENV} or ./log-store)",
    )


def _quiet_libraries() -> None:
    for name in ("paramiko", "botocore", "boto3", "s3transfer", "urllib3"):
        logging.getLogger(name).setLevel(logging.WARNING)


def _deliver(args: argparse.Namespace) -> int:
    from orchestrator import progress
    from orchestrator.delivery import deliver_pending

    _quiet_libraries()
    store = args.store or default_store()
    if not store.is_dir():  # not made here: a mistyped --store would leave an empty one
        if not args.json:  # (--json: one line per outcome, none here)
            print("nothing to deliver" + _no_store(store))
        return ExitCode.OK
    with progress() as bars:
        outcomes = deliver_pending(store, team=args.team, progress=bars)
    for outcome in outcomes:
        print(json.dumps(outcome.to_json()) if args.json else _describe_outcome(outcome))
    if not outcomes and not args.json:
        print("nothing to deliver")
    return ExitCode.OK if all(o.delivered for o in outcomes) else ExitCode.FAILED


def _describe_outcome(outcome: DeliveryOutcome) -> str:
    head = f"{outcome.match_id} {outcome.team} -> {outcome.target}"
    if outcome.delivered:
        return (
            f"delivered {head}: {outcome.uploaded_files} files uploaded, "
            f"{outcome.skipped_files} already there, {outcome.uploaded_bytes / 1e6:.1f} MB "
            f"in {outcome.seconds:.1f} s"
        )
    assert outcome.error is not None
    from orchestrator.delivery import ERROR_KINDS

    hint = ERROR_KINDS.get(outcome.error.kind, "")
    return f"FAILED {head} ({outcome.error.kind}: {hint}): {outcome.error.reason}"


def _status(args: argparse.Namespace) -> int:
    from orchestrator.delivery import pending_status

    store = args.store or default_store()
    sets = pending_status(store)
    if args.json:
        print(json.dumps([s.to_json() for s in sets], indent=2))
        return ExitCode.OK
    if not sets:
        print("no log sets are waiting" + _no_store(store))
    for pending in sets:
        print(_describe_set(pending))
    return ExitCode.OK


def _no_store(store: Path) -> str:
    """Said after "nothing waiting" when the store folder is not there (a command run from
    another folder than the match's, whose default store is ./log-store)."""
    if store.is_dir():
        return ""
    return (f": there is no log store at {store} (--store DIR or ${STORE_ENV} names the one "
            "the matches queued to)")


def _describe_set(pending: PendingSet) -> str:
    created = time.strftime("%Y-%m-%d %H:%M:%S", time.gmtime(pending.created_ns / 1e9))
    text = (
        f"{pending.match_id} {pending.team}: {len(pending.files)} files, "
        f"{pending.total_bytes / 1e6:.1f} MB, queued {created} UTC, "
        f"{pending.attempts} attempts"
    )
    if pending.last_error is not None:
        text += f", last error ({pending.last_error.kind}): {pending.last_error.reason}"
    return text


def _enqueue(args: argparse.Namespace) -> int:
    from orchestrator.config import load_game

    if not args.match_dir.is_dir():
        raise ConfigError(
            [
                Problem(
                    str(args.match_dir),
                    "",
                    "no such match folder",
                    "the output folder of a finished match",
                )
            ]
        )
    loaded = load_game(args.game)
    game = loaded.game
    teams = {
        color: (loaded.team(color).name, game.team(color).credentials) for color in ("red", "blue")
    }
    from orchestrator.delivery import enqueue_match_logs

    sets = enqueue_match_logs(
        args.match_dir,
        match_id=args.match_id or game.match_id,
        teams=teams,
        public_target=game.public_logs,
        store=args.store or default_store(),
        move_team_logs=not args.copy,
    )
    if args.json:
        print(json.dumps([s.to_json() for s in sets], indent=2))
        return ExitCode.OK
    for pending in sets:
        print(
            f"queued {pending.match_id} {pending.team}: {len(pending.files)} files, "
            f"{pending.total_bytes / 1e6:.1f} MB"
        )
    return ExitCode.OK
