"""Whatever a file holds, `hlvs check` answers 0 or 2 with clean lines, never a traceback."""

from __future__ import annotations

import contextlib
import io
import json
import tempfile
from pathlib import Path
from typing import Any

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from hlvs.cli import main
from tests.unit.config.conftest import valid_game, valid_team

KEYS = st.sampled_from(
    [
        "type",
        "class",
        "host",
        "red",
        "blue",
        "players",
        "name",
        "ports",
        "id",
        "config",
        "hosts",
        "1",
        "halfTimeStartingPose",
        "translation",
        "rotation",
        "maximum_real_time_factor",
    ]
) | st.text(max_size=8)
SCALARS = (
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**70), max_value=2**70)
    | st.floats(allow_nan=False, allow_infinity=False)
    | st.text(max_size=12)
)
JSON_VALUES = st.recursive(
    SCALARS,
    lambda inner: st.lists(inner, max_size=4) | st.dictionaries(KEYS, inner, max_size=5),
    max_leaves=20,
)


def _check(folder: Path, name: str, data: bytes, *extra: str) -> tuple[int, str]:
    path = folder / name
    path.write_bytes(data)
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["check", *extra, str(path)])
    text = out.getvalue() + err.getvalue()
    assert code in (0, 2), text
    assert "Traceback" not in text
    for line in out.getvalue().splitlines():
        assert line.startswith((str(folder), f"warning: {folder}")), line
    return code, text


def _folder() -> Path:
    return Path(tempfile.mkdtemp(prefix="hlvs-check-"))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(value=JSON_VALUES)
def test_arbitrary_json_values(value: Any) -> None:
    folder = _folder()
    _check(folder, "game.json", json.dumps(value).encode())
    _check(folder, "team.json", json.dumps(value).encode(), "--kind", "team")


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.binary(max_size=200))
def test_arbitrary_bytes(data: bytes) -> None:
    _check(_folder(), "input.json", data)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    section=st.sampled_from(["game", "red", "blue", "team", "player", "pose"]),
    key=KEYS,
    value=JSON_VALUES,
)
def test_one_field_replaced_in_a_valid_game(section: str, key: str, value: Any) -> None:
    folder = _folder()
    game, team = valid_game(), valid_team()
    target: dict[str, Any] = {
        "game": game,
        "red": game["red"],
        "blue": game["blue"],
        "team": team,
        "player": team["players"]["2"],
        "pose": team["players"]["2"]["halfTimeStartingPose"],
    }[section]
    target[key] = value
    (folder / "team_red.json").write_text(json.dumps(team), encoding="utf-8")
    (folder / "team_blue.json").write_text(json.dumps(valid_team()), encoding="utf-8")
    _check(folder, "game.json", json.dumps(game).encode())
