"""Input that used to pass ``hlvs check`` and fail later: each is now an error naming the file,
the field and what is allowed, and ``hlvs match`` stops before creating anything."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from hlvs.cli import main as hlvs
from orchestrator import add_scrimmage_arguments
from orchestrator.match import scrimmage


def _files(folder: Path) -> Path:
    parser = argparse.ArgumentParser()
    add_scrimmage_arguments(parser)
    args = parser.parse_args(["--red-image", "team/red:1", "--blue-image", "team/blue:1",
                              "--match-id", "hostile-config"])
    return scrimmage.write_files(scrimmage.ScrimmageRequest.from_options(args), folder)


def _edit(path: Path, **changes: object) -> None:
    data = json.loads(path.read_text())
    for key, value in changes.items():
        if isinstance(value, dict):
            data.setdefault(key, {}).update(value)
        else:
            data[key] = value
    path.write_text(json.dumps(data, indent=2))


def _check(path: Path, capsys: pytest.CaptureFixture[str]) -> tuple[int, list[str]]:
    code = hlvs(["check", str(path)])
    captured = capsys.readouterr()
    return code, (captured.out + captured.err).splitlines()


@pytest.mark.parametrize("port", [7447, 3838, 3939, 3737])
def test_a_robot_port_on_a_simulator_port(tmp_path: Path, port: int,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    game = _files(tmp_path)
    _edit(game, red={"ports": [port]})
    code, lines = _check(game, capsys)
    assert code == 2
    assert any(f"/red/ports/0: port {port} is the simulator's port" in line for line in lines)


@pytest.mark.parametrize(("field", "value", "bounds"), [
    ("memory_gb", 1e-6, ">= 0.064 and <= 4096"),
    ("log_folder_gb", 1e6, ">= 0.01 and <= 1000"),
    ("cpus", 0.001, ">= 0.1 and <= 256"),
    ("scratch_gb", 1e9, ">= 0.01 and <= 1000"),
])
def test_limits_outside_sane_bounds(tmp_path: Path, field: str, value: float, bounds: str,
                                    capsys: pytest.CaptureFixture[str]) -> None:
    game = _files(tmp_path)
    _edit(game, limits={field: value})
    code, lines = _check(game, capsys)
    assert code == 2
    assert any(f"/limits/{field}:" in line and bounds in line for line in lines), lines


def test_duplicate_keys_name_both_lines(tmp_path: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    game = _files(tmp_path)
    text = game.read_text().replace('"seed": 42,', '"seed": 42,\n  "seed": 7,', 1)
    game.write_text(text)
    first = text.splitlines().index('  "seed": 42,') + 1
    code, lines = _check(game, capsys)
    assert code == 2
    assert any(f'key "seed" appears twice: at line {first} and at line {first + 1}' in line
               for line in lines), lines


@pytest.mark.parametrize("name", [
    "nul\x00", "esc\x1b[31m", "bidi\u202eevil", "new\nline", "a/b", "a\\b", "N" * 100_000,
])
def test_bad_team_names(tmp_path: Path, name: str, capsys: pytest.CaptureFixture[str]) -> None:
    game = _files(tmp_path)
    _edit(tmp_path / "team_red.json", name=name)
    code, lines = _check(game, capsys)
    assert code == 2
    bad = [line for line in lines if "team_red.json: /name:" in line]
    assert bad and all(len(line) < 400 for line in lines), lines


def test_match_stops_before_creating_anything(tmp_path: Path,
                                              capsys: pytest.CaptureFixture[str]) -> None:
    game = _files(tmp_path / "config")
    _edit(game, limits={"log_folder_gb": 1e6})
    out = tmp_path / "out"
    assert hlvs(["match", str(game), "--out", str(out)]) == 2
    assert "log_folder_gb" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize(("pointer", "value"), [
    ("/texture_seed", -1), ("/texture_seed", 1e30), ("/maximum_real_time_factor", 1e30),
    ("/lockstep_deadline_ms", 1e30), ("/lockstep_time_bank_ms", 1e30),
    ("/timing/half_duration_s", 1e30), ("/timing/ready_duration_s", 1e30),
    ("/timing/grace_period_s", 1e30), ("/timing/minimum_play_s", 1e30),
    ("/timing/wait_before_first_ready_s", 1e30), ("/timing/removal_penalty_s", 1e30),
    ("/timing/half_time_break_s", 1e30), ("/timing/overtime_half_duration_s", 1e30),
])
def test_operator_fields_out_of_range_fail_the_check(
        tmp_path: Path, pointer: str, value: float, capsys: pytest.CaptureFixture[str]) -> None:
    """As found: texture_seed -1 or 1e30 passed hlvs check and failed in the simulator."""
    game = _files(tmp_path)
    parts = pointer.strip("/").split("/")
    _edit(game, **({parts[0]: value} if len(parts) == 1 else {parts[0]: {parts[1]: value}}))
    code, lines = _check(game, capsys)
    assert code == 2, lines
    assert any(pointer in line for line in lines), lines
