"""``hlvs serve`` and ``hlvs admin``: parse arguments, wire objects, map errors to exit codes.

``hlvs admin`` works on the service's database directly (same settings as ``hlvs serve``:
``HLVS_SERVICE_*`` variables, or ``--data-dir`` / ``--database-url``), so the first operator
token can be issued before the service runs. Without any of them it uses ``./service-data``
only when a database is there already: run from another folder than the service, it would
otherwise make a new, empty database and issue tokens the service never sees.
"""

from __future__ import annotations

import argparse
import errno
import functools
import json
import logging
import socket
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

from orchestrator import user_path
from service import ServiceError, Settings


def guarded(func: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
    """Service errors become one line on stderr and their exit code (no traceback)."""

    @functools.wraps(func)
    def run(args: argparse.Namespace) -> int:
        try:
            return func(args)
        except ServiceError as exc:
            print(f"hlvs: {exc}", file=sys.stderr)
            return exc.exit_code

    return run


def _settings(args: argparse.Namespace) -> Settings:
    settings = Settings.from_env()
    changes: dict[str, Path | str] = {}
    if getattr(args, "data_dir", None) is not None:
        changes["data_dir"] = args.data_dir
    if getattr(args, "database_url", None):
        changes["database_url"] = args.database_url
    return settings.with_(**changes) if changes else settings


def _add_db_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--data-dir", type=user_path, default=None,
                        help="folder of the service's files (default: $HLVS_SERVICE_DATA_DIR "
                             "or ./service-data, which hlvs admin uses only when a database "
                             "is there already)")
    parser.add_argument("--database-url", default=None,
                        help="SQLAlchemy URL (default: $HLVS_SERVICE_DATABASE_URL or SQLite in "
                             "the data folder)")


def register(sub: Any) -> None:
    serve = sub.add_parser("serve", help="run the submission service (HTTP API)")
    serve.add_argument("--host", default="127.0.0.1",
                       help="address to listen on (default 127.0.0.1)")
    serve.add_argument("--port", type=int, default=8000, help="TCP port (default 8000)")
    serve.add_argument("--no-worker", action="store_true",
                       help="serve the API without starting matches")
    _add_db_options(serve)
    serve.set_defaults(func=guarded(run_serve), log_level=logging.INFO)

    admin = sub.add_parser("admin", help="teams and tokens of the submission service")
    admin_sub = admin.add_subparsers(dest="admin_command", metavar="WHAT", required=True)
    team = admin_sub.add_parser("team", help="teams").add_subparsers(
        dest="team_command", metavar="ACTION", required=True)
    add = team.add_parser("add", help="add a team")
    add.add_argument("name", help="team name, as in its team_config.json")
    add.add_argument("--email", default=None, help="where the team's mail goes")
    add.add_argument("--accepts-friendlies", action="store_true",
                     help="other teams may ask for test matches against this team")
    _add_db_options(add)
    add.set_defaults(func=guarded(run_team_add))
    listing = team.add_parser("list", help="list teams")
    _add_db_options(listing)
    listing.set_defaults(func=guarded(run_team_list))

    token = admin_sub.add_parser("token", help="API tokens").add_subparsers(
        dest="token_command", metavar="ACTION", required=True)
    issue = token.add_parser("issue", help="issue a token (printed once; only its hash is kept)")
    who = issue.add_mutually_exclusive_group(required=True)
    who.add_argument("--team", help="a team token for this team")
    who.add_argument("--operator", action="store_true", help="an operator token")
    issue.add_argument("--days", type=float, default=None,
                       help="lifetime in days (default: $HLVS_SERVICE_TOKEN_DAYS, 90)")
    issue.add_argument("--no-expiry", action="store_true", help="a token that never expires")
    issue.add_argument("--label", default="", help="a note shown in 'token list'")
    issue.add_argument("--json", action="store_true", help="print a JSON object")
    _add_db_options(issue)
    issue.set_defaults(func=guarded(run_token_issue))
    revoke = token.add_parser("revoke", help="revoke a token by its id")
    revoke.add_argument("token_id", help="the id part of hlvs_<id>_<secret>")
    _add_db_options(revoke)
    revoke.set_defaults(func=guarded(run_token_revoke))
    tlist = token.add_parser("list", help="list tokens (ids, scopes, expiry; never secrets)")
    _add_db_options(tlist)
    tlist.set_defaults(func=guarded(run_token_list))

    from hlvs.commands.client import register_client_commands

    register_client_commands(sub, guarded)
    bench = sub.choices.get("bench")
    if bench is not None:
        from hlvs.commands.forwarding import forward

        kinds = next(a for a in bench._actions if isinstance(a, argparse._SubParsersAction))
        forward(kinds, "service", help="the submission service under 200 polling and 20 "
                                       "submitting clients (JSON)", func=_bench)


def _bench(args: argparse.Namespace) -> int:
    from benchmarks import service as service_bench

    return int(service_bench.main(list(args.rest)))


def _told_where(args: argparse.Namespace) -> bool:
    """Whether the command was told which database to use (an option or a variable), rather
    than taking ``./service-data`` of whatever folder it runs in."""
    import os

    given = (getattr(args, "data_dir", None) is not None, getattr(args, "database_url", None))
    names = ("HLVS_SERVICE_DATA_DIR", "HLVS_SERVICE_DATABASE_URL")
    return any(given) or any(os.environ.get(name) for name in names)


def _check_database(args: argparse.Namespace, settings: Settings) -> None:
    """Refuse to make a new, empty database in the current folder by accident: ``hlvs admin``
    run from another folder than ``hlvs serve`` would issue tokens the service never sees."""
    from orchestrator import ConfigError, Problem

    if settings.database_url or _told_where(args):
        return
    database = (settings.data_dir / "service.sqlite").resolve()
    if database.is_file():
        return
    raise ConfigError([Problem(
        "(command line)", "--data-dir",
        f"no service database at {database}: hlvs admin works on the database of hlvs serve, "
        "which is ./service-data of the folder the service runs in unless "
        "HLVS_SERVICE_DATA_DIR or HLVS_SERVICE_DATABASE_URL says otherwise",
        expected="this command run from the service's folder, or --data-dir DIR (a new folder "
        "makes a new database)",
    )])


def _sessions(args: argparse.Namespace) -> Any:
    from service import open_data_dir, open_database
    from service.db import session_factory

    settings = _settings(args)
    _check_database(args, settings)
    open_data_dir(settings)
    return session_factory(open_database(settings))


def run_serve(args: argparse.Namespace) -> int:
    import uvicorn

    from hlvs.app import create_app
    from service import open_storage

    settings = _settings(args)
    listener = _listen(args.host, args.port)  # before anything starts: a busy port is one line
    try:
        storage = open_storage(settings)
        app = create_app(settings, start_worker=not args.no_worker, storage=storage)
        config = uvicorn.Config(app, host=args.host, port=args.port, log_level="info",
                                access_log=False, timeout_keep_alive=int(settings.keep_alive_s))
        shown = f"[{args.host}]" if ":" in args.host else args.host
        port = listener.getsockname()[1]  # (--port 0: the one the system chose)
        logging.getLogger("hlvs.serve").info(
            "the service listens on http://%s:%d (Ctrl+C stops it)", shown, port)
        uvicorn.Server(config).run(sockets=[listener])
    finally:
        listener.close()
    return 0


def _listen(host: str, port: int) -> socket.socket:
    """The service's listening socket on ``host``:``port``, bound before the service starts
    (uvicorn binds after the app's startup, whose worker may already have taken a queued
    match when the port turns out to be taken)."""
    from orchestrator import ConfigError, Problem

    # as uvicorn binds: IPv6 for an address with a colon, else IPv4 ("localhost" is 127.0.0.1)
    listener = socket.socket(socket.AF_INET6 if ":" in host else socket.AF_INET)
    try:
        listener.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        listener.bind((host, port))
        listener.listen(2048)
    except OSError as exc:
        listener.close()
        busy = exc.errno == errno.EADDRINUSE
        raise ConfigError([Problem(
            "(command line)", "--port" if busy else "--host",
            f"cannot listen on {host}:{port}: {exc.strerror or exc}",
            expected="a port nothing else listens on (another hlvs serve?)" if busy
            else "an address of this host and a port this user may open",
        )]) from exc
    return listener


def run_team_add(args: argparse.Namespace) -> int:
    from cluster import PoolError
    from service import add_team
    from service.db import Team, transaction

    settings = _settings(args)
    with transaction(_sessions(args)) as session:
        team = add_team(session, name=args.name, email=args.email,
                        accepts_friendlies=args.accepts_friendlies)
        session.flush()
        result: dict[str, object] = {"team": team.name, "id": team.id}
    if settings.pool == "slurm":  # the team's Slurm account now (else at its first match)
        from service import ensure_team_account, pool_from_settings

        with transaction(_sessions(args)) as session:
            row = session.get(Team, team.id)
            assert row is not None
            try:
                result["slurm_account"] = ensure_team_account(session, pool_from_settings(settings),
                                                              row, settings)
            except PoolError as exc:
                print(f"hlvs: warning: no Slurm account yet ({exc}); it is made before the "
                      "team's first test match", file=sys.stderr)
    print(json.dumps(result))
    return 0


def run_team_list(args: argparse.Namespace) -> int:
    from sqlalchemy import select

    from service.db import Team, transaction

    with transaction(_sessions(args)) as session:
        for team in session.scalars(select(Team).order_by(Team.name)):
            print(json.dumps({"team": team.name, "email": team.email,
                              "accepts_friendlies": team.accepts_friendlies}))
    return 0


def run_token_issue(args: argparse.Namespace) -> int:
    from service import tokens
    from service.db import Scope, transaction

    days = None if args.no_expiry else (args.days if args.days is not None
                                        else _settings(args).token_days)
    with transaction(_sessions(args)) as session:
        issued = tokens.issue(session, scope=Scope.OPERATOR if args.operator else Scope.TEAM,
                              team=args.team, days=days, label=args.label)
    if args.json:
        print(json.dumps({
            "token": issued.secret, "id": issued.token_id, "scope": issued.scope.value,
            "team": issued.team,
            "expires_at": issued.expires_at.isoformat(timespec="seconds")
            if issued.expires_at else None,
        }))
    else:
        print(issued.secret)
    return 0


def run_token_revoke(args: argparse.Namespace) -> int:
    from service import tokens
    from service.db import transaction

    with transaction(_sessions(args)) as session:
        tokens.revoke(session, args.token_id)
    print(json.dumps({"revoked": args.token_id}))
    return 0


def run_token_list(args: argparse.Namespace) -> int:
    from service import list_tokens
    from service.db import transaction

    with transaction(_sessions(args)) as session:
        for row in list_tokens(session):
            print(json.dumps(row))
    return 0


__all__ = ["guarded", "register"]
