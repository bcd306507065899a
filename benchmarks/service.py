"""``hlvs bench service``: the service under load on loopback; prints one JSON line.

One ``hlvs serve`` process (its queue worker running, the queue paused so no match starts,
the pre-flight check in ``images`` mode: the team's images are inspected on the real engine,
no robot is started). Then, for ``--duration`` seconds:

- ``--pollers`` clients (200) each poll the status of their team's queued submission every
  ``--interval`` seconds (1 s), the way a team's dashboard or script would;
- ``--submitters`` clients (20) each submit a test match, then cancel it (a queued cancel), once
  every ``--submit-interval`` seconds (2 s), all starting together.

Reported: p50 / p99 / max latency and errors per kind of request (an error is any answer other
than the expected status code, or no answer within 10 s), the server's CPU time per request and
the host's load average before and after and how late the client's own event loop woke up
(latency on a shared host depends on both). Target: no
errors and a status p99 under 200 ms.
"""

from __future__ import annotations

import argparse
import asyncio
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from testkit.figures import process_cpu_s

TARGET_STATUS_P99_MS = 200.0


def _parse(argv: Sequence[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="hlvs bench service", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--pollers", type=int, default=200, help="status-polling clients")
    parser.add_argument("--submitters", type=int, default=20, help="submitting clients")
    parser.add_argument("--duration", type=float, default=30.0, help="seconds of load")
    parser.add_argument("--interval", type=float, default=1.0,
                        help="seconds between two status polls of one client")
    parser.add_argument("--submit-interval", type=float, default=2.0,
                        help="seconds between two submissions of one submitter")
    parser.add_argument("--database-url", default=None,
                        help="SQLAlchemy URL of an empty database (default: SQLite in a "
                             "temporary folder)")
    parser.add_argument("--port", type=int, default=0, help="port (default: a free one)")
    parser.add_argument("--json", action="store_true", help="print only the JSON line")
    return parser.parse_args(list(argv))


def _free_port() -> int:
    import socket

    with socket.socket() as sock:
        sock.bind(("127.0.0.1", 0))
        port: int = sock.getsockname()[1]
        return port


def _percentiles(samples: list[float], expected: int, errors: int) -> dict[str, Any]:
    ordered = sorted(samples)

    def pick(q: float) -> float | None:
        if not ordered:
            return None
        return round(ordered[min(len(ordered) - 1, int(q * len(ordered)))] * 1000, 2)

    return {"requests": len(samples) + errors, "ok": len(samples), "errors": errors,
            "p50_ms": pick(0.5), "p99_ms": pick(0.99),
            "max_ms": round(max(ordered) * 1000, 2) if ordered else None,
            "mean_ms": round(statistics.fmean(ordered) * 1000, 2) if ordered else None,
            "expected_status": expected}


class Kind:
    def __init__(self, expected: int) -> None:
        self.expected = expected
        self.samples: list[float] = []
        self.errors = 0
        self.error_examples: list[str] = []

    def record(self, started: float, status: int | None, text: str = "") -> bool:
        if status == self.expected:
            self.samples.append(time.perf_counter() - started)
            return True
        self.errors += 1
        if len(self.error_examples) < 3:
            self.error_examples.append(f"{status}: {text[:200]}")
        return False


def _setup(database_url: str, data_dir: Path, teams: int) -> tuple[list[str], str]:
    """Teams T0000.. with one token each, and an operator token (direct database access)."""
    from service.admin import add_team
    from service.db import Scope, make_engine, migrate, session_factory, transaction
    from service.tokens import issue

    engine = make_engine(database_url)
    migrate(engine)
    factory = session_factory(engine)
    tokens = []
    with transaction(factory) as session:
        for n in range(teams):
            add_team(session, name=f"T{n:04d}")
            tokens.append(issue(session, scope=Scope.TEAM, team=f"T{n:04d}", days=1).secret)
        operator = issue(session, scope=Scope.OPERATOR, team=None, days=1).secret
    engine.dispose()
    return tokens, operator


class _Connection:
    """One keep-alive HTTP/1.1 connection that sends GETs with a bearer token: far less client
    CPU per request than a general client, so that the client's share of a small host goes
    to the server under test."""

    def __init__(self, url: str, token: str) -> None:
        host, _, port = url.removeprefix("http://").partition(":")
        self.host, self.port = host, int(port)
        self.token = token
        self.reader: asyncio.StreamReader | None = None
        self.writer: asyncio.StreamWriter | None = None

    async def get(self, path: str) -> tuple[int, str]:
        if self.writer is None or self.reader is None:
            self.reader, self.writer = await asyncio.open_connection(self.host, self.port)
        self.writer.write((f"GET {path} HTTP/1.1\r\nHost: {self.host}\r\n"
                           f"Authorization: Bearer {self.token}\r\n\r\n").encode())
        head = (await self.reader.readuntil(b"\r\n\r\n")).decode("latin-1")
        status_line, *lines = head.split("\r\n")
        length = 0
        for line in lines:
            name, _, value = line.partition(":")
            if name.strip().lower() == "content-length":
                length = int(value)
        body = await self.reader.readexactly(length)
        return int(status_line.split(" ", 2)[1]), body.decode(errors="replace")

    def close(self) -> None:
        if self.writer is not None:
            self.writer.close()
        self.reader = self.writer = None


async def _load(url: str, args: argparse.Namespace, tokens: list[str], operator: str,
                team_doc: dict[str, Any], on_load_start: Callable[[], None]
                ) -> dict[str, Any]:
    import httpx

    limits = httpx.Limits(max_connections=args.pollers + args.submitters + 10,
                          keepalive_expiry=10.0)  # below the server's keep-alive (30 s)
    async with httpx.AsyncClient(base_url=url, timeout=10.0, limits=limits) as http:
        def auth(token: str) -> dict[str, str]:
            return {"Authorization": f"Bearer {token}"}

        paused = await http.post("/v1/operator/queue/pause", headers=auth(operator))
        paused.raise_for_status()
        for n, token in enumerate(tokens):
            doc = {**team_doc, "name": f"T{n:04d}"}
            (await http.put("/v1/team/files/team_config", json=doc,
                            headers=auth(token))).raise_for_status()
        poll_ids = []
        for token in tokens[:args.pollers]:
            answer = await http.post("/v1/submissions", json={}, headers=auth(token))
            answer.raise_for_status()
            poll_ids.append(answer.json()["id"])

        status, submit, cancel = Kind(200), Kind(201), Kind(200)
        stop_at = time.perf_counter() + args.duration

        async def poller(token: str, sid: str, offset: float) -> None:
            await asyncio.sleep(offset)
            connection = _Connection(url, token)
            next_at = time.perf_counter()
            try:
                while time.perf_counter() < stop_at:
                    started = time.perf_counter()
                    try:
                        code, text = await asyncio.wait_for(
                            connection.get(f"/v1/submissions/{sid}"), 10.0)
                        status.record(started, code, text)
                    except (OSError, EOFError, ValueError, asyncio.LimitOverrunError) as exc:
                        status.record(started, None, repr(exc))
                        connection.close()
                    next_at += args.interval
                    await asyncio.sleep(max(0.0, next_at - time.perf_counter()))
            finally:
                connection.close()

        async def submitter(token: str) -> None:
            next_at = time.perf_counter()
            while time.perf_counter() < stop_at:
                await asyncio.sleep(max(0.0, next_at - time.perf_counter()))
                next_at += args.submit_interval
                started = time.perf_counter()
                try:
                    answer = await http.post("/v1/submissions", json={}, headers=auth(token))
                    if not submit.record(started, answer.status_code, answer.text):
                        continue
                    sid = answer.json()["id"]
                    started = time.perf_counter()
                    answer = await http.post(f"/v1/submissions/{sid}/cancel",
                                             headers=auth(token))
                    cancel.record(started, answer.status_code, answer.text)
                except httpx.HTTPError as exc:
                    submit.record(started, None, repr(exc))

        lags: list[float] = []

        async def lag_monitor() -> None:
            """How late the client's own event loop wakes up (the host's share of CPU)."""
            while time.perf_counter() < stop_at:
                asked = time.perf_counter()
                await asyncio.sleep(0.1)
                lags.append(max(0.0, time.perf_counter() - asked - 0.1))

        began = time.perf_counter()
        on_load_start()
        tasks = [lag_monitor()]
        tasks += [poller(t, s, args.interval * i / max(1, len(poll_ids)))
                 for i, (t, s) in enumerate(zip(tokens[:args.pollers], poll_ids, strict=True))]
        tasks += [submitter(t) for t in tokens[args.pollers:]]
        await asyncio.gather(*tasks)
        elapsed = time.perf_counter() - began
    result = {
        "status": _percentiles(status.samples, 200, status.errors),
        "submit": _percentiles(submit.samples, 201, submit.errors),
        "cancel": _percentiles(cancel.samples, 200, cancel.errors),
        "elapsed_s": round(elapsed, 2),
        "client_loop_lag_ms": {
            "p50": round(sorted(lags)[len(lags) // 2] * 1000, 1) if lags else None,
            "p99": round(sorted(lags)[int(len(lags) * 0.99)] * 1000, 1) if lags else None},
    }
    examples = status.error_examples + submit.error_examples + cancel.error_examples
    if examples:
        result["error_examples"] = examples
    return result


def main(argv: Sequence[str]) -> int:
    args = _parse(argv)
    from orchestrator.project_images import project_image

    stub = project_image("stub")
    repository, _, tag = stub.rpartition(":")
    example = Path(__file__).parents[1] / "configs" / "examples" / "scrimmage_1v1" / \
        "team_red.json"
    team_doc = json.loads(example.read_text())
    team_doc["image"] = repository
    team_doc["players"]["1"]["dockerTag"] = tag
    with tempfile.TemporaryDirectory(prefix="hlvs-bench-service-") as folder:
        data = Path(folder) / "data"  # the service's key file goes beside it, in folder
        data.mkdir(mode=0o700)
        database = args.database_url or f"sqlite:///{data / 'service.sqlite'}"
        tokens, operator = _setup(database, data, args.pollers + args.submitters)
        port = args.port or _free_port()
        env = {**os.environ, "HLVS_SERVICE_PREFLIGHT": "images",
               "HLVS_SERVICE_TEAM_PROJECT_IMAGES": "1",  # the teams play the project's stub
               "HLVS_SERVICE_DATA_DIR": str(data), "HLVS_SERVICE_DATABASE_URL": database}
        log_path = data / "serve.log"
        with log_path.open("wb") as log_file:
            server = subprocess.Popen(
                [sys.executable, "-m", "hlvs", "-q", "serve", "--port", str(port)],
                env=env, stdout=log_file, stderr=subprocess.STDOUT)
        try:
            url = f"http://127.0.0.1:{port}"
            _wait_ready(url, server, log_path)
            before: dict[str, float] = {}

            def on_load_start() -> None:  # after the teams' files and submissions are in
                before.update(load=os.getloadavg()[0], server=_cpu_s(server.pid),
                              client=time.process_time())

            result = asyncio.run(_load(url, args, tokens, operator, team_doc, on_load_start))
            server_cpu = _cpu_s(server.pid) - before["server"]
            client_cpu = time.process_time() - before["client"]
            load_after = os.getloadavg()[0]
        finally:
            server.terminate()
            try:
                server.wait(timeout=60)
            except subprocess.TimeoutExpired:
                server.kill()
                server.wait()
                print("hlvs bench service: the server did not stop within 60 s of SIGTERM; "
                      "killed. Its log ends with:\n"
                      + log_path.read_text(errors="replace")[-3000:], file=sys.stderr)
    errors = sum(result[k]["errors"] for k in ("status", "submit", "cancel"))
    requests = sum(result[k]["requests"] for k in ("status", "submit", "cancel"))
    result["server_cpu_s"] = round(server_cpu, 2)
    result["client_cpu_s"] = round(client_cpu, 2)
    result["server_cpu_ms_per_request"] = round(server_cpu / max(1, requests) * 1000, 2)
    result["load_average_1min"] = [round(before["load"], 2), round(load_after, 2)]
    p99 = result["status"]["p99_ms"]
    output = {
        "bench": "service",
        "database": database.split(":", 1)[0].split("+")[0],
        "pollers": args.pollers, "submitters": args.submitters,
        "duration_s": args.duration, "poll_interval_s": args.interval,
        "submit_interval_s": args.submit_interval,
        "preflight": "images", "cpus": os.cpu_count(),
        **result,
        "target": {"errors": 0, "status_p99_ms": TARGET_STATUS_P99_MS},
        "ok": errors == 0 and p99 is not None and p99 < TARGET_STATUS_P99_MS,
    }
    if not args.json:
        print(f"status p50 {result['status']['p50_ms']} ms, p99 {p99} ms, errors {errors}",
              file=sys.stderr)
    print(json.dumps(output, sort_keys=True))
    return 0 if output["ok"] else 1


def _cpu_s(pid: int) -> float:
    """CPU seconds (user + system) used so far by process ``pid``, which is running."""
    seconds = process_cpu_s(pid)
    if seconds is None:
        raise RuntimeError(f"the CPU time of process {pid} cannot be read from /proc")
    return seconds


def _wait_ready(url: str, server: subprocess.Popen[bytes], log_path: Path) -> None:
    import httpx

    deadline = time.monotonic() + 60
    while time.monotonic() < deadline:
        if server.poll() is not None:
            raise SystemExit(f"hlvs serve exited with {server.returncode}: "
                             + log_path.read_text(errors="replace")[-2000:])
        try:
            if httpx.get(url + "/v1/health", timeout=2).status_code == 200:
                return
        except httpx.HTTPError:
            pass
        time.sleep(0.2)
    raise SystemExit(f"hlvs serve did not answer on {url} within 60 s")


__all__ = ["main"]
