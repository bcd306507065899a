"""``hlvs schedule run|list|status|cancel|abort|reschedule|apply|standings|export``: a
tournament from one schedule file, the operator's controls over it, and its results."""

from __future__ import annotations

import argparse
import json
import logging
import os
import sys
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

from orchestrator import ConfigError, Problem, ScheduleError, user_path

_STATE_HELP = "SQLite state file written by 'hlvs schedule run'"


def register(sub: Any) -> None:
    parser: argparse.ArgumentParser = sub.add_parser(
        "schedule", help="run a tournament from a schedule file (pull, play, deliver)"
    )
    verbs = parser.add_subparsers(dest="verb", metavar="VERB")
    verbs.required = True
    for add in (_add_run, _add_views, _add_controls, _add_results):  # in the help's order
        add(verbs)


def _add_run(verbs: Any) -> None:
    run = verbs.add_parser("run", help="run the schedule; survives restarts")
    run.add_argument("schedule", type=user_path, help="schedule file (YAML)")
    run.add_argument(
        "--state", type=user_path, required=True, help="SQLite state file (jobs and ledger)"
    )
    run.add_argument("--exit-when-done", action="store_true", help="stop when every match is final")
    run.add_argument("--services", help="module:factory of the pull/play/deliver services (tests)")
    run.add_argument("--pool", choices=("local", "slurm"), default=None,
                     help="where matches run: this host's Docker engine or one Slurm job per "
                     "match (default: the schedule's pool section, else local); remembered in "
                     "the state file")
    run.add_argument("--stop-grace", type=float, default=None, metavar="S",
                     help="on SIGTERM or Ctrl-C, seconds a playing match has to stop and collect "
                     "its logs before it is killed (default 60; a supervisor's stop timeout, "
                     "e.g. systemd's TimeoutStopSec, should be longer); remembered in the state "
                     "file. The match is played again at the next start")
    run.add_argument("--notify-mail", action="append", default=[], metavar="ADDRESS",
                     help="mail the operators at ADDRESS (repeatable) when a match is FAILED, "
                     "MISSED or LOGS_FAILED, still running when its stream starts, or the "
                     "scheduler stopped; remembered in the state file")
    run.add_argument("--notify-webhook", action="append", default=[], metavar="URL",
                     help="POST the same notices, signed as the service's webhooks "
                     "(X-HLVS-Signature), to URL (repeatable; needs --notify-webhook-secret-file)")
    run.add_argument("--notify-webhook-secret-file", type=user_path, metavar="FILE",
                     help="file holding the webhooks' shared secret")
    run.add_argument("--smtp", default="localhost:25", metavar="HOST[:PORT]",
                     help="SMTP server of the mails (default localhost:25)")
    run.add_argument("--mail-from", default="hlvs@localhost", metavar="ADDRESS",
                     help="sender of the mails (default hlvs@localhost)")
    run.set_defaults(func=_run, log_level=logging.INFO)


def _add_views(verbs: Any) -> None:
    """list and status."""
    plan = verbs.add_parser("list", help="what is planned, with absolute times")
    plan.add_argument("schedule", type=user_path, help="schedule file (YAML)")
    plan.add_argument(
        "--state", type=user_path, help="the times this tournament's state file keeps "
        "(rescheduled and applied ones), with each match's state"
    )
    plan.add_argument("--json", action="store_true", help="print a JSON array")
    plan.set_defaults(func=_list)

    status = verbs.add_parser("status", help="state of every match")
    status.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    status.add_argument("--json", action="store_true", help="print a JSON array")
    status.add_argument("--watch", action="store_true",
                        help="print the status again every --every seconds until Ctrl-C")
    status.add_argument("--every", type=float, default=2.0, metavar="S",
                        help="seconds between two prints with --watch (default 2)")
    status.set_defaults(func=_status)


def _add_controls(verbs: Any) -> None:
    """The operator's controls: cancel, abort, reschedule, apply."""
    cancel = verbs.add_parser("cancel", help="cancel a match that is not played yet")
    cancel.add_argument("match_id", help="id of the match in the schedule")
    cancel.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    cancel.set_defaults(func=_cancel)

    stop = verbs.add_parser(
        "abort", help="stop a running match (SIGTERM, a grace period, then SIGKILL); the "
        "match becomes ABORTED with the reason")
    stop.add_argument("match_id", help="id of the match in the schedule")
    stop.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    stop.add_argument("--reason", required=True, help="why (recorded with the match)")
    stop.add_argument("--grace", type=float, default=None, metavar="S",
                      help="seconds the match has to stop and collect its logs before it is "
                      "killed (default 150)")
    stop.set_defaults(func=_abort)

    again = verbs.add_parser(
        "reschedule", help="plan a match again: un-cancel it, or give it a new time")
    again.add_argument("match_id", help="id of the match in the schedule")
    again.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    again.add_argument("--at", metavar="TIME",
                       help="new stream start: ISO 8601 with a time zone, or +30m from now "
                       "(default: the schedule's time)")
    again.set_defaults(func=_reschedule)

    apply = verbs.add_parser(
        "apply", help="make the edited schedule file the tournament's (until then the copy "
        "recorded at the start runs on)")
    apply.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    apply.set_defaults(func=_apply)


def _add_results(verbs: Any) -> None:
    """export and standings."""
    export = verbs.add_parser(
        "export", help="the results for the league's website: matches (scores, shoot-outs), "
        "standings, bracket")
    export.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    export.add_argument("--format", choices=("json", "csv"), default="json",
                        help="json: one document with every table (default); csv: one table")
    export.add_argument("--table", choices=("matches", "standings"), default="matches",
                        help="the table --format csv writes (default matches)")
    export.add_argument("--out", type=user_path, metavar="FILE",
                        help="write to FILE (default: standard output)")
    export.set_defaults(func=_export)

    table = verbs.add_parser("standings", help="points, goal difference and goals")
    table.add_argument("--state", type=user_path, required=True, help=_STATE_HELP)
    table.add_argument("--json", action="store_true", help="print a JSON array")
    table.set_defaults(func=_standings)


def _ledger(path: Path) -> Any:
    from tournament import Ledger

    if not path.is_file():
        raise ConfigError(
            [Problem(str(path), "", "no such state file", "the --state file of hlvs schedule run")]
        )
    return Ledger(path)


def _run(args: argparse.Namespace) -> int:
    from orchestrator.config import check_schedule
    from tournament import run_schedule

    recorded = args.state.is_file() and _ledger(args.state).get_meta("schedule_text")
    if not recorded:  # the first run: what hlvs check finds is refused before any pull (a
        # restart runs the copy checked then; an edit waits for 'hlvs schedule apply')
        problems = check_schedule(args.schedule, now=datetime.now(UTC))
        if any(p.severity == "error" for p in problems):
            raise ConfigError(problems)

    if args.stop_grace is not None and args.stop_grace < 0:
        raise ConfigError([Problem("--stop-grace", "", f"{args.stop_grace:g}",
                                   expected="seconds, 0 or more")])
    code = run_schedule(
        args.schedule, args.state, services=args.services, pool=args.pool,
        exit_when_done=args.exit_when_done, stop_grace_s=args.stop_grace,
        notify=_notify_settings(args),
    )
    from tournament import STOPPING

    if STOPPING.is_set():
        # stopped by a signal: a step that cannot be interrupted (an image pull) must not keep
        # the process; the state file is consistent at any instant and the next start takes
        # the step up again
        logging.shutdown()
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(code)
    return code


def _notify_settings(args: argparse.Namespace) -> str | None:
    """The --notify-* options as the state file records them (None: keep the recorded ones)."""
    from tournament import NotifySettings, Webhook

    if not args.notify_mail and not args.notify_webhook:
        return None
    problems = []
    for i, url in enumerate(args.notify_webhook):
        if not url.startswith(("http://", "https://")):
            problems.append(Problem("--notify-webhook", f"/{i}", f"{url!r} is not a URL",
                                    expected="an http:// or https:// URL"))
    secret_file: Path | None = args.notify_webhook_secret_file
    if args.notify_webhook and secret_file is None:
        problems.append(Problem("--notify-webhook-secret-file", "", "missing",
                                expected="a file holding the webhooks' shared secret"))
    elif secret_file is not None and not secret_file.is_file():
        problems.append(Problem(str(secret_file), "", "file not found",
                                expected="a file holding the webhooks' shared secret"))
    for address in args.notify_mail:
        if "@" not in address:
            problems.append(Problem("--notify-mail", "", f"{address!r} is not a mail address",
                                    expected="user@host"))
    host, _, port = args.smtp.partition(":")
    if not host or (port and not port.isdigit()):
        problems.append(Problem("--smtp", "", f"{args.smtp!r}", expected="HOST or HOST:PORT"))
    if problems:
        raise ConfigError(problems)
    settings = NotifySettings(
        mail_to=tuple(args.notify_mail), smtp_host=host, smtp_port=int(port or 25),
        mail_from=args.mail_from,
        webhooks=tuple(Webhook(url=u, secret="") for u in args.notify_webhook))
    return settings.recorded(secret_file.resolve() if secret_file else None)


def _list(args: argparse.Namespace) -> int:
    from orchestrator.config import load_schedule, resolve_time

    schedule = load_schedule(args.schedule)
    now = datetime.now(UTC)
    reference = now
    if schedule.start not in (None, "now"):
        reference = resolve_time(str(schedule.start), now)
    if args.state:
        ledger = _ledger(args.state)
        _warn_differences(ledger)
        classes = {m.id: m.field_class for m in schedule.matches}
        rows = [  # the times the tournament keeps (rescheduled, applied), not the file's
            {
                "id": r.id,
                "kind": r.kind,
                "class": classes.get(r.id, ""),
                "red": r.red,
                "blue": r.blue,
                "pull_at": r.pull_at.isoformat(timespec="seconds"),
                "play_at": r.play_at.isoformat(timespec="seconds"),
                "stream_start": r.stream_start.isoformat(timespec="seconds"),
                "deliver_at": r.deliver_at.isoformat(timespec="seconds"),
                "state": r.state.value,
            }
            for r in ledger.rows()
        ]
        _print_plan(rows, as_json=args.json)
        return 0
    rows = [
        {
            "id": p.match.id,
            "kind": p.match.kind,
            "class": p.match.field_class,
            "red": str(p.match.red),
            "blue": str(p.match.blue),
            "pull_at": p.pull_at.isoformat(timespec="seconds"),
            "play_at": p.play_at.isoformat(timespec="seconds"),
            "stream_start": p.stream_start.isoformat(timespec="seconds"),
            "deliver_at": p.deliver_at.isoformat(timespec="seconds"),
        }
        for p in sorted(schedule.plan(reference), key=lambda p: (p.stream_start, p.match.id))
    ]
    _print_plan(rows, as_json=args.json)
    return 0


def _print_plan(rows: list[dict[str, str]], *, as_json: bool) -> None:
    if as_json:
        print(json.dumps(rows, indent=2))
        return
    for r in rows:
        state = f" ({r['state']})" if "state" in r else ""
        print(
            f"{r['id']:<12} {r['kind']:<11} {r['red']} v {r['blue']}: pull {r['pull_at']},"
            f" play {r['play_at']}, stream {r['stream_start']}{state}"
        )


def _status(args: argparse.Namespace) -> int:
    from tournament import Snapshot, scheduler_state, status_lines

    snapshot: Snapshot | None = None
    if not args.json:  # a running match's score and clock, from its telemetry
        from viewer import game_snapshot

        snapshot = game_snapshot
    if not args.watch:
        ledger = _ledger(args.state)
        if args.json:
            print(json.dumps([r.as_dict() for r in ledger.rows()], indent=2))
        else:
            alive = scheduler_state(ledger)
            print("\n".join(([alive.text] if alive.text else [])
                            + status_lines(ledger, snapshot=snapshot)))
        _warn_differences(ledger)
        return 0
    import time

    try:
        ledger = _wait_for_state(args.state, args.every, quiet_stdout=args.json)
        while True:
            alive = scheduler_state(ledger)
            if not alive.running:
                _notify_dead(ledger, alive)
            if args.json:
                text = json.dumps([r.as_dict() for r in ledger.rows()])
            else:
                text = "\n".join(([alive.text] if alive.text else [])
                                 + status_lines(ledger, snapshot=snapshot))
                print("\x1b[H\x1b[2J", end="")  # clear the terminal, as watch(1) does
                print(f"{datetime.now(UTC).isoformat(timespec='seconds')}"
                      f"  (every {args.every:g} s, Ctrl-C to stop)")
            print(text, flush=True)
            time.sleep(args.every)
    except KeyboardInterrupt:
        return 0


def _wait_for_state(path: Path, every_s: float, *, quiet_stdout: bool = False) -> Any:
    """``status --watch`` started before ``run``: wait until the state file is written (the
    line saying so goes to stderr with ``--json``, which keeps stdout JSON only)."""
    import time

    from tournament import Ledger

    said = False
    while not path.is_file() or not Ledger(path).get_meta("schedule_text"):
        if not said:
            print(f"waiting for {path} (written by 'hlvs schedule run'; Ctrl-C to stop)",
                  file=sys.stderr if quiet_stdout else sys.stdout, flush=True)
            said = True
        time.sleep(every_s)
    return Ledger(path)


def _notify_dead(ledger: Any, alive: Any) -> None:
    """A scheduler that stopped beating cannot tell: the watching operator's command does,
    with the notification settings the scheduler recorded."""
    from tournament import Outbox, recorded_settings

    settings = recorded_settings(ledger)
    if settings.any and alive.waiting and alive.since is not None:
        outbox = Outbox(ledger, settings)
        outbox.add(f"scheduler.stopped|{alive.since.isoformat()}", "scheduler.stopped",
                   {"tournament": outbox.name, "text": alive.text,
                    "since": alive.since.isoformat()})
        outbox.send_due()


def _cancel(args: argparse.Namespace) -> int:
    from tournament import ScheduledMatchState

    ledger = _ledger(args.state)
    not_started = (
        ScheduledMatchState.PLANNED,
        ScheduledMatchState.PULLING,
        ScheduledMatchState.PULLED,
    )
    if not ledger.transition(
        args.match_id, not_started, ScheduledMatchState.CANCELLED, note="cancelled"
    ):
        try:
            state = ledger.row(args.match_id).state.value
        except KeyError:
            raise ScheduleError(f"no match {args.match_id!r} in {args.state}") from None
        raise ScheduleError(
            f"match {args.match_id} is {state}; only matches not yet played can be cancelled"
        )
    print(f"{args.match_id}: CANCELLED")
    return 0


def _abort(args: argparse.Namespace) -> int:
    from tournament import DEFAULT_ABORT_GRACE_S, abort

    grace = DEFAULT_ABORT_GRACE_S if args.grace is None else args.grace
    abort(_ledger(args.state), args.match_id, reason=args.reason, grace_s=grace)
    print(f"{args.match_id}: abort requested ({args.reason}); the scheduler stops it within "
          f"{grace:g} s and marks it ABORTED")
    return 0


def _reschedule(args: argparse.Namespace) -> int:
    from tournament import reschedule

    planned = reschedule(_ledger(args.state), args.match_id, at=args.at)
    print(f"{args.match_id}: PLANNED, pull {planned.pull_at.isoformat(timespec='seconds')}, "
          f"stream {planned.stream_start.isoformat(timespec='seconds')}")
    return 0


def _apply(args: argparse.Namespace) -> int:
    from tournament import apply_file

    changes = apply_file(_ledger(args.state))
    for change in changes or ["no change"]:
        print(change)
    return 0


def _warn_differences(ledger: Any) -> None:
    from tournament import file_differences

    for note in file_differences(ledger):
        print(f"warning: {note}", file=sys.stderr)


def _export(args: argparse.Namespace) -> int:
    import io

    from tournament import export_document, write_csv

    document = export_document(_ledger(args.state))
    if args.format == "json":
        text = json.dumps(document, indent=2) + "\n"
    else:
        buffer = io.StringIO()
        write_csv(document, args.table, buffer)
        text = buffer.getvalue()
    if args.out is None:
        sys.stdout.write(text)
        return 0
    try:
        args.out.write_text(text, encoding="utf-8")
    except OSError as exc:
        raise ConfigError([Problem(str(args.out), "", f"cannot be written: {exc.strerror}",
                                   expected="a file in a folder that exists")]) from None
    table = args.table if args.format == "csv" else "matches"
    print(f"{args.out}: {len(document[table])} {table}")
    return 0


def _standings(args: argparse.Namespace) -> int:
    from tournament import recorded_schedule, standings

    ledger = _ledger(args.state)
    schedule = recorded_schedule(ledger)
    table = standings(ledger.rows(), [t.name for t in schedule.teams], seed=schedule.name)
    if args.json:
        print(json.dumps([s.as_dict() for s in table], indent=2))
        return 0
    print(
        f"{'team':<16} {'P':>3} {'W':>3} {'D':>3} {'L':>3} {'GF':>4} {'GA':>4} {'GD':>4} {'Pts':>4}"
    )
    for s in table:
        tie = f"  (above the next on points by {s.decided_by})" if s.decided_by else ""
        print(
            f"{s.team:<16} {s.played:>3} {s.won:>3} {s.drawn:>3} {s.lost:>3} {s.goals_for:>4}"
            f" {s.goals_against:>4} {s.goal_difference:>4} {s.points:>4}{tie}"
        )
    return 0
