"""The command-line client (hlvs submit|status|cancel|results, hlvs logs fetch) and the
automated-submission example, against the served app with a pool whose matches succeed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

import pytest

from cluster.fake import FakePool
from hlvs.cli import main
from service import Settings
from tests.integration.service.harness import Served, free_port, serve
from tests.unit.service.conftest import FakePreflight, team_doc

REPO = Path(__file__).parents[3]


@pytest.fixture
def served(settings: Settings) -> Iterator[Served]:
    pool = FakePool(auto_finish=True)
    instance = serve(settings, start_worker=True, pool_factory=lambda _s: pool,
                     preflight=FakePreflight())
    yield instance
    instance.stop()


def hlvs(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def test_submit_wait_status_results_logs(served: Served, token: object, tmp_path: Path,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert callable(token)
    token_file = tmp_path / "token"
    token_file.write_text(token("Alpha") + "\n")
    team_file = tmp_path / "team_config.json"
    team_file.write_text(json.dumps(team_doc("Alpha")))
    common = ["--server", served.url, "--token-file", str(token_file)]
    code, out, err = hlvs(capsys, "submit", *common, "--team-config", str(team_file),
                          "--wait", "--poll", "0.1")
    assert code == 0, err
    final = json.loads(out)
    assert final["state"] == "done"
    assert "stored as team_config version 1" in err
    sid = final["id"]

    code, out, _ = hlvs(capsys, "status", *common, sid)
    assert code == 0 and json.loads(out)["id"] == sid
    code, out, _ = hlvs(capsys, "status", *common)
    assert code == 0 and [s["id"] for s in json.loads(out)] == [sid]

    code, out, _ = hlvs(capsys, "results", *common, sid, "--out", str(tmp_path / "r"))
    assert code == 0
    assert sorted(json.loads(out)["files"]) == ["replay.hlvsrec", "report.json", "results.json"]
    report = json.loads((tmp_path / "r" / "report.json").read_text())
    assert report["status"] == "success" and report["backend_error"] is False

    code, out, _ = hlvs(capsys, "logs", "fetch", *common, sid, "--out", str(tmp_path / "l"))
    assert code == 0
    assert (tmp_path / "l" / "team" / "1" / "stdout.log").read_text() == "red robot log\n"
    assert (tmp_path / "l" / "public" / "referee.log").is_file()
    assert not (tmp_path / "l" / "team" / "blue").exists()

    code, _, err = hlvs(capsys, "cancel", *common, sid)
    assert code == 2 and "HTTP 409" in err and "already ended" in err
    token_text = token_file.read_text().strip()
    assert token_text not in out + err


def test_client_errors(served: Served, tmp_path: Path, capsys: pytest.CaptureFixture[str],
                       monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("HLVS_SERVER", raising=False)
    monkeypatch.setenv("HLVS_TOKEN", "hlvs_000000000000_" + "x" * 43)
    monkeypatch.setenv("HOME", str(tmp_path))
    code, _, err = hlvs(capsys, "status")
    assert code == 2 and "--server" in err
    code, _, err = hlvs(capsys, "status", "--server", served.url)
    assert code == 2 and "HTTP 401" in err and "not known" in err
    code, _, err = hlvs(capsys, "status", "--server", f"http://127.0.0.1:{free_port()}")
    assert code == 3 and "no answer" in err
    monkeypatch.delenv("HLVS_TOKEN")
    code, _, err = hlvs(capsys, "status", "--server", served.url)
    assert code == 2 and "no token" in err


def test_automated_submission_example(served: Served, token: object, tmp_path: Path) -> None:
    assert callable(token)
    team_file = tmp_path / "team_config.json"
    team_file.write_text(json.dumps(team_doc("Alpha")))
    env = {**os.environ, "HLVS_SERVER": served.url, "HLVS_TOKEN": token("Alpha"),
           "PATH": f"{Path(sys.executable).parent}:{os.environ['PATH']}"}
    script = REPO / "configs" / "examples" / "service" / "auto_submit.sh"
    done = subprocess.run(["bash", str(script), str(team_file), "2"], cwd=tmp_path, env=env,
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "round 2 of 2 done" in done.stdout
    assert "backend_error=False, user_returncode=0" in done.stdout
    runs = sorted(p.name for p in (tmp_path / "runs").iterdir())
    assert len(runs) == 2
    assert (tmp_path / "runs" / runs[0] / "logs" / "team" / "1" / "stdout.log").is_file()
