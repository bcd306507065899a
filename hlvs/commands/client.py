"""The command-line client of the service: ``hlvs submit|status|cancel|results`` and
``hlvs logs fetch``, each with ``--server URL`` (or ``$HLVS_SERVER``).

The token comes from ``--token-file FILE``, else ``$HLVS_TOKEN``, else the file
``~/.config/hlvs/token``; it is sent as ``Authorization: Bearer`` and never printed. Every
answer is printed as JSON on stdout. Exit codes: 0 success (``submit --wait``: the match
played to its end), 1 the match failed or was cancelled, 2 refused (bad input, unknown id,
409, pre-flight failure, no or bad token), 3 no answer from the server.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

from orchestrator import user_path

DEFAULT_TOKEN_FILE = Path("~/.config/hlvs/token")
FINAL_STATES = ("done", "failed", "cancelled")


def register_client_commands(sub: Any, guarded: Callable[[Any], Any]) -> None:
    submit = sub.add_parser("submit", help="ask the league's service for a test match")
    _common(submit)
    submit.add_argument("--team-config", type=user_path, default=None,
                        help="upload this team_config.json first (a new version)")
    submit.add_argument("--credentials", type=user_path, default=None,
                        help="upload this credentials.json (log delivery) first")
    submit.add_argument("--opponent", default="stub",
                        help="'stub' (default) or a team that accepts friendlies")
    submit.add_argument("--wait", action="store_true",
                        help="poll until the match has ended; exit 0 only when it played")
    submit.add_argument("--poll", type=float, default=5.0,
                        help="seconds between polls with --wait (default 5)")
    submit.set_defaults(func=guarded(run_submit))

    status = sub.add_parser("status", help="a test match's state, queue position and "
                                           "expected start (all of them without ID)")
    _common(status)
    status.add_argument("submission", nargs="?", default=None,
                        help="submission id (sub_...); default: list the team's submissions")
    status.set_defaults(func=guarded(run_status))

    cancel = sub.add_parser("cancel", help="cancel a queued (free) or running test match")
    _common(cancel)
    cancel.add_argument("submission", help="submission id (sub_...)")
    cancel.set_defaults(func=guarded(run_cancel))

    results = sub.add_parser("results", help="download report.json, results.json, the replay "
                                             "and the video of a test match")
    _common(results)
    results.add_argument("submission", help="submission id (sub_...)")
    results.add_argument("-o", "--out", type=user_path, default=None,
                         help="folder to write into (default: ./<submission id>)")
    results.set_defaults(func=guarded(run_results))

    logs_parser = sub.choices.get("logs")
    if logs_parser is not None:
        actions = next(a for a in logs_parser._actions
                       if isinstance(a, argparse._SubParsersAction))
        fetch = actions.add_parser("fetch", help="download a test match's logs from the "
                                                 "league's service (own team and public)")
        _common(fetch)
        fetch.add_argument("submission", help="submission id (sub_...)")
        fetch.add_argument("-o", "--out", type=user_path, default=None,
                           help="folder to write into (default: ./<submission id>/logs)")
        fetch.set_defaults(func=guarded(run_logs))


def _common(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--server", default=None, metavar="URL",
                        help="the service's URL, e.g. https://hlvs.example.org "
                             "(default: $HLVS_SERVER)")
    parser.add_argument("--token-file", type=user_path, default=None, metavar="FILE",
                        help="a file holding the team token; without this option the token "
                             "is the value of the variable HLVS_TOKEN, else the content of "
                             "the file ~/.config/hlvs/token")


class Api:
    """A thin httpx client that turns error answers into :class:`ClientError`."""

    def __init__(self, server: str, token: str) -> None:
        import httpx

        self.server = server.rstrip("/")
        self._http = httpx.Client(base_url=self.server, timeout=120,
                                  headers={"Authorization": f"Bearer {token}"})

    def close(self) -> None:
        self._http.close()

    def call(self, method: str, path: str, **kwargs: Any) -> Any:
        import httpx

        from service import ClientError

        try:
            answer = self._http.request(method, path, **kwargs)
        except httpx.HTTPError as exc:
            raise ClientError(url=self.server + path, status=None, message=str(exc)) from exc
        if answer.status_code >= 400:
            try:
                body = answer.json()
                message = str(body.get("message", answer.text))
                if body.get("existing_id"):
                    message += f" (existing: {body['existing_id']})"
                for problem in body.get("problems", [])[:20]:
                    message += "\n  " + str(problem.get("text") or problem)
            except ValueError:
                message = answer.text[:500]
            raise ClientError(url=self.server + path, status=answer.status_code,
                              message=message)
        if answer.headers.get("content-type", "").startswith("application/json"):
            return answer.json()
        return answer.content


def _api(args: argparse.Namespace) -> Api:
    from service import InvalidInput

    server = args.server or os.environ.get("HLVS_SERVER")
    if not server:
        raise InvalidInput("no server: give --server URL or set HLVS_SERVER")
    server = server_url(server, given="--server" if args.server else "$HLVS_SERVER")
    token: str | None
    if args.token_file is not None:
        token = _read_token(args.token_file)
    else:
        token = os.environ.get("HLVS_TOKEN") or None
        default = DEFAULT_TOKEN_FILE.expanduser()
        if token is None and default.is_file():
            token = _read_token(default)
    if not token:
        raise InvalidInput("no token: give --token-file FILE, set HLVS_TOKEN or write it to "
                           "~/.config/hlvs/token")
    return Api(server, token)


def server_url(text: str, *, given: str) -> str:
    """``text`` as the service's base URL; InvalidInput (exit 2) for one without ``http://`` or
    ``https://`` and a host, naming where it came from (``given``: the option or variable)."""
    from urllib.parse import urlsplit

    from service import InvalidInput

    url = text.strip()
    parts = urlsplit(url)
    if parts.scheme not in ("http", "https") or not parts.netloc:
        hint = f"; did you mean http://{url}?" if "://" not in url and url else ""
        raise InvalidInput(f"{given}: {text!r} is not the service's URL: expected http:// or "
                           f"https:// then the host, e.g. http://127.0.0.1:8000{hint}")
    return url


def _read_token(path: Path) -> str:
    from service import InvalidInput

    try:
        return path.expanduser().read_text(encoding="utf-8").strip()
    except OSError as exc:
        raise InvalidInput(f"{path}: cannot read the token file: {exc.strerror}") from None


def _load_json(path: Path) -> Any:
    from service import InvalidInput

    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InvalidInput(f"{path}: cannot read the file: {exc.strerror}") from None
    except json.JSONDecodeError as exc:
        raise InvalidInput(f"{path}: invalid JSON at line {exc.lineno} column {exc.colno}: "
                           f"{exc.msg}") from None


def inline_key(document: Any, source: Path) -> Any:
    """credentials.json with an SFTP ``private_key`` path replaced by the key's text (read
    here, on the team's machine: the service reads no path). Left as it is when unreadable,
    for the service to say so."""
    body = document.get("credentials") if isinstance(document, dict) else None
    key = body.get("private_key") if isinstance(body, dict) else None
    if not isinstance(body, dict) or not isinstance(key, str) or \
            key.lstrip().startswith("-----BEGIN"):
        return document
    path = Path(key).expanduser()
    path = path if path.is_absolute() else source.parent / path
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return document
    return {**document, "credentials": {**body, "private_key": text}}


def _print(data: Any) -> None:
    print(json.dumps(data, indent=2, sort_keys=True))


def run_submit(args: argparse.Namespace) -> int:
    api = _api(args)
    try:
        for kind, path in (("team_config", args.team_config), ("credentials", args.credentials)):
            if path is not None:
                document = _load_json(path)
                if kind == "credentials":
                    document = inline_key(document, path)
                stored = api.call("PUT", f"/v1/team/files/{kind}", json=document)
                print(f"hlvs: {path} stored as {kind} version {stored['version']}",
                      file=sys.stderr)
        status = api.call("POST", "/v1/submissions", json={"opponent": args.opponent})
        if not args.wait:
            _print(status)
            return 0
        print(f"hlvs: {status['id']} queued; waiting for it to end", file=sys.stderr)
        last = None
        while status["state"] not in FINAL_STATES:
            line = (f"{status['state']}"
                    + (f", position {status['queue_position']}" if status.get("queue_position")
                       else "")
                    + (f", {status['waiting_reason']}" if status.get("waiting_reason") else ""))
            if line != last:
                print(f"hlvs: {status['id']}: {line}", file=sys.stderr)
                last = line
            time.sleep(args.poll)
            status = api.call("GET", f"/v1/submissions/{status['id']}")
        _print(status)
        return 0 if status["state"] == "done" else 1
    finally:
        api.close()


def run_status(args: argparse.Namespace) -> int:
    api = _api(args)
    try:
        path = "/v1/submissions" + (f"/{args.submission}" if args.submission else "")
        _print(api.call("GET", path))
        return 0
    finally:
        api.close()


def run_cancel(args: argparse.Namespace) -> int:
    api = _api(args)
    try:
        _print(api.call("POST", f"/v1/submissions/{args.submission}/cancel"))
        return 0
    finally:
        api.close()


def run_results(args: argparse.Namespace) -> int:
    from pydantic import ValidationError

    from contracts import files
    from service import ClientError, SubmissionReport

    api = _api(args)
    out: Path = args.out or Path(args.submission)
    try:
        out.mkdir(parents=True, exist_ok=True)
        where = f"/v1/submissions/{args.submission}/report"
        report = api.call("GET", where)
        try:
            state = SubmissionReport.model_validate(report).state
        except ValidationError as exc:
            raise ClientError(url=where, status=200,
                              message=f"not a submission report: {exc}") from exc
        (out / files.REPORT).write_text(json.dumps(report, indent=2) + "\n")
        written = [files.REPORT]
        for name, path in ((files.RESULTS, "results"), (files.REPLAY, "replay"),
                           (files.VIDEO, "video")):
            try:
                data = api.call("GET", f"/v1/submissions/{args.submission}/{path}")
            except ClientError as exc:
                if exc.status == 404:
                    continue  # not produced (yet): the match has not ended, or no video
                raise
            content = data if isinstance(data, bytes) else json.dumps(data, indent=2).encode()
            (out / name).write_bytes(content)
            written.append(name)
        _print({"submission": args.submission, "state": state, "folder": str(out),
                "files": written})
        return 0
    finally:
        api.close()


def run_logs(args: argparse.Namespace) -> int:
    """Download the listed logs into ``--out``. A listed name is written only when it is a
    relative path under ``--out`` that passes no symlink: an absolute name, ``..``, an empty
    or ``.`` part, a NUL, or a folder on the way that is a symlink is refused (named on
    stderr, exit 2), and nothing is written for it."""
    from service import ClientError

    api = _api(args)
    out: Path = args.out or Path(args.submission) / "logs"
    try:
        listing = api.call("GET", f"/v1/submissions/{args.submission}/logs")
        written: list[str] = []
        refused: list[dict[str, str]] = []
        for part in ("team", "public"):
            for name in listing[part]:
                problem = unsafe_name(name)
                if problem is not None:
                    refused.append({"name": f"{part}/{name}", "reason": problem})
                    continue
                data = api.call("GET", f"/v1/submissions/{args.submission}/logs/{part}/{name}")
                problem = write_under(out, f"{part}/{name}", data if isinstance(data, bytes)
                                      else json.dumps(data).encode())
                if problem is not None:
                    refused.append({"name": f"{part}/{name}", "reason": problem})
                    continue
                written.append(f"{part}/{name}")
        for entry in refused:
            print(f"hlvs: {entry['name']!a}: not written: {entry['reason']}", file=sys.stderr)
        _print({"submission": args.submission, "folder": str(out), "files": written,
                "refused": refused})
        if refused:
            raise ClientError(url=f"/v1/submissions/{args.submission}/logs", status=422,
                              message=f"{len(refused)} listed name(s) refused (not under "
                                      f"{out})")
        return 0
    finally:
        api.close()


def unsafe_name(name: object) -> str | None:
    """Why a listed log name may not be written under the output folder (None: it may)."""
    if not isinstance(name, str) or not name:
        return "not a file name"
    if "\0" in name:
        return "a NUL in the name"
    if name.startswith("/") or (len(name) > 1 and name[1] == ":"):
        return "an absolute path"
    parts = name.split("/")
    if any(p in ("", ".", "..") for p in parts):
        return "an empty, '.' or '..' part (outside the output folder)"
    return None


def write_under(root: Path, name: str, data: bytes) -> str | None:
    """Write ``data`` to ``root/name`` without following a symlink anywhere below ``root``;
    why not, when it cannot be."""
    folder = root
    folder.mkdir(parents=True, exist_ok=True)
    *parents, leaf = name.split("/")
    for part in parents:
        folder = folder / part
        if folder.is_symlink():
            return f"{folder} is a symlink"
        try:
            folder.mkdir(exist_ok=True)
        except FileExistsError:
            return f"{folder} is not a folder"
        if not folder.is_dir() or folder.is_symlink():
            return f"{folder} is not a folder"
    target = folder / leaf
    try:
        fd = os.open(target, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_NOFOLLOW, 0o644)
    except OSError as exc:
        return f"{target}: {exc.strerror}"
    with os.fdopen(fd, "wb") as handle:
        handle.write(data)
    return None


__all__ = ["Api", "register_client_commands"]
