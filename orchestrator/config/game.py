"""game.json: schema, per-file rules, and the GameConfig it becomes.

Team files are not read here (see :mod:`orchestrator.config.loader`); this module checks what
game.json alone can tell: required fields, legacy names, GameController arguments, port clashes,
referenced files.
"""

from __future__ import annotations

import hashlib
import os
import re
from pathlib import Path
from typing import Any, Literal, cast

from contracts import timing_problem
from orchestrator.config.documents import GameDocument, GameTeamDocument
from orchestrator.config.model import (
    COLORS,
    Color,
    FieldClass,
    GameConfig,
    Limits,
    TeamRef,
    Timing,
)
from orchestrator.config.problems import Collector, pointer
from orchestrator.config.schema import validate

LEGACY_RTF: tuple[Literal["minimum_real_time_factor", "real_time_factor"], ...] = (
    "minimum_real_time_factor", "real_time_factor",
)
# Real time, as the league's official matches run; used when game.json names no factor at all
# (several of the league's own game files have neither the current nor a legacy name).
DEFAULT_MAXIMUM_REAL_TIME_FACTOR = 1.0
BASIC_TIME_STEP_S = 0.008
FAST_WAIT_BEFORE_FIRST_READY_S = 5.0
FAST_HALF_TIME_BREAK_S = 2.0
_GC_DURATION_OPTIONS = {
    "--halftimeduration": "half_duration_s",
    "-d": "half_duration_s",
    "--overtimeduration": "overtime_half_duration_s",
    "-o": "overtime_half_duration_s",
}


def default_match_id(source: Path, red_id: int, blue_id: int) -> str:
    """``<file stem>-<red id>-vs-<blue id>``, reduced to the characters a match id allows."""
    stem = re.sub(r"[^A-Za-z0-9_.-]+", "-", source.stem).strip("-._") or "match"
    return f"{stem[:40]}-{red_id}-vs-{blue_id}"


def default_seed(match_id: str) -> int:
    """A 32-bit seed derived from the match id (the same id always gives the same seed)."""
    return int.from_bytes(hashlib.sha256(match_id.encode("utf-8")).digest()[:4], "big")


def _overlaps(bad: str, part: str) -> bool:
    """True when a problem at ``bad`` makes the value at ``part`` unusable."""
    return bad in ("", part) or bad.startswith(part + "/") or part.startswith(bad + "/")


def team_id(raw: Any) -> int:
    return int(raw)


def build_game(document: Any, where: Collector, *, source: Path) -> GameConfig | None:
    """Validate one game document; the GameConfig when it has no error (problems in ``where``).

    The rules after the schema run on every part the schema found sound, so one pass reports
    as many problems as possible.
    """
    before = len(where.errors)
    validate("game", document, where)
    if not isinstance(document, dict):
        return None
    game = cast("GameDocument", document)  # the schema checked it; the rules read sound parts
    broken = [p.pointer for p in where.errors[before:]]

    def sound(*parts: str) -> bool:
        return not any(_overlaps(bad, part) for bad in broken for part in parts)

    base = source.parent
    rtf = None
    if sound("/maximum_real_time_factor", *(pointer(n) for n in LEGACY_RTF)):
        rtf = _real_time_factor(game, where)
    timing = Timing()
    if sound("/timing", "/game_controller_extra_args", "/max_duration"):
        timing = _timing(game, where, fast=rtf is not None and rtf <= 0)
    if sound("/physics_dt_s"):
        _check_physics_dt(game, where)
    _check_record(game, where)
    if sound("/red/id", "/blue/id"):
        _check_team_ids(game, where)
    if sound("/red/ports", "/blue/ports"):
        _check_ports(game, where)
    teams = {
        color: _team_ref(color, game[color], base, where)
        for color in COLORS
        if sound(pointer(color))
    }
    public_logs = None
    if sound("/public_logs"):
        public_logs = _existing(game.get("public_logs"), base, "/public_logs", where)
    if len(where.errors) > before or rtf is None:
        return None
    red, blue = teams["red"], teams["blue"]
    match_id = game.get("match_id") or default_match_id(source, red.team_id, blue.team_id)
    seed = game.get("seed", game.get("random_seed"))
    if "seed" not in game and "random_seed" in game:
        where.warn("/random_seed", "legacy field: used as the match seed", expected='"seed"')
    return GameConfig(
        source=source,
        match_id=match_id,
        seed=seed if seed is not None else default_seed(match_id),
        game_type=game["type"],
        field_class=FieldClass(str(game["class"]).lower()),
        host=game["host"],
        maximum_real_time_factor=rtf,
        red=red,
        blue=blue,
        side_left=game.get("side_left", "random"),
        kickoff=game.get("kickoff", "random"),
        press_a_key_to_terminate=game.get("press_a_key_to_terminate", False),
        use_bouncing_server=game.get("use_bouncing_server", False),
        record_simulation=game.get("record_simulation"),
        game_controller_extra_args=tuple(game.get("game_controller_extra_args", ())),
        texture_seed=game.get("texture_seed"),
        sensors=game.get("sensors", "league"),
        camera_motion_blur=game.get("camera_motion_blur", False),
        supervisor=game.get("supervisor"),
        stepping=game.get("stepping", "async"),
        physics_dt_s=float(game.get("physics_dt_s", 0.002)),
        lockstep_deadline_ms=float(game.get("lockstep_deadline_ms", 50.0)),
        lockstep_time_bank_ms=float(game.get("lockstep_time_bank_ms", 5000.0)),
        limits=_limits(game.get("limits", {})),
        timing=timing,
        allow_internet=game.get("allow_internet", False),
        official=game.get("official", False),
        registry_images=bool(game.get("registry_images", game.get("official", False))),
        gpu=game.get("gpu", "auto"),
        public_logs=public_logs,
    )


def legacy_maximum_real_time_factor(value: float) -> float:
    """The maximum real-time factor a legacy ``minimum_real_time_factor`` (or the 2021
    ``real_time_factor``) ``value`` means. The league's referee before March 2023 (``referee.py``)
    made each basic time step last at least ``value`` times its simulated time, so the
    simulation ran at most ``1 / value`` times real time; 0 ran as fast as possible."""
    return 1.0 / value if value > 0 else 0.0


def default_real_time_factor(stepping: str) -> float:
    """The pace of a match whose file we write (a scrimmage, a schedule's match) when nothing
    else sets it: real time in async stepping, which never waits for the robots (as fast as
    possible, the faster the host, the fewer control steps they would get); as fast as possible
    in lockstep and pipelined stepping, which wait for them."""
    return DEFAULT_MAXIMUM_REAL_TIME_FACTOR if stepping == "async" else 0.0


def _real_time_factor(document: GameDocument, where: Collector) -> float:
    """The game's maximum real-time factor (problems with its fields in ``where``), warned
    about when it is as fast as possible in async stepping."""
    name, rtf = _read_real_time_factor(document, where)
    if rtf <= 0 and document.get("stepping", "async") == "async":
        where.warn(
            pointer(name),
            "as fast as possible with async stepping: the simulation never waits for the "
            "robots and runs as fast as this host can, so the robots get fewer control steps "
            "the faster it is",
            expected='1 (real time, as the league plays) or "stepping": "lockstep"',
        )
    return rtf


def _read_real_time_factor(document: GameDocument, where: Collector) -> tuple[str, float]:
    """The field the factor was read from (the league's default: ``maximum_real_time_factor``)
    and the factor."""
    legacy = [name for name in LEGACY_RTF if name in document]
    if "maximum_real_time_factor" in document:
        for name in legacy:
            where.warn(
                pointer(name), "legacy field: ignored", expected='"maximum_real_time_factor"'
            )
        return "maximum_real_time_factor", float(document["maximum_real_time_factor"])
    if legacy:
        name = legacy[0]
        value = float(document[name])
        maximum = legacy_maximum_real_time_factor(value)
        meaning = (
            f"each 8 ms step lasts at least {value:g} x 8 ms of wall time, read as "
            f"maximum_real_time_factor {maximum:g}"
            if maximum > 0
            else f"{value:g} runs as fast as possible (maximum_real_time_factor 0)"
        )
        where.warn(pointer(name), f"legacy field: {meaning}", expected='"maximum_real_time_factor"')
        return name, maximum
    where.warn(
        "/maximum_real_time_factor",
        f"missing: the league's default {DEFAULT_MAXIMUM_REAL_TIME_FACTOR:g} (real time) is used",
        expected="a number (<= 0: as fast as possible)",
    )
    return "maximum_real_time_factor", DEFAULT_MAXIMUM_REAL_TIME_FACTOR


def timing_of(document: GameDocument, where: Collector, *, fast: bool) -> Timing:
    """The timing of a game document (``timing``, ``game_controller_extra_args``, ``type``),
    its problems in ``where``; also used for a schedule's ``game_defaults``."""
    return _timing(document, where, fast=fast)


def _timing(document: GameDocument, where: Collector, *, fast: bool) -> Timing:
    """Timing from ``timing`` and the GameController arguments.

    As in HLVS, a game run as fast as possible (maximum_real_time_factor <= 0) waits only 5 s
    before the first READY and 2 s at half time unless ``timing`` says otherwise.
    """
    written: dict[str, float] = dict(document.get("timing", {}))
    if fast:
        written.setdefault("wait_before_first_ready_s", FAST_WAIT_BEFORE_FIRST_READY_S)
        written.setdefault("half_time_break_s", FAST_HALF_TIME_BREAK_S)
    from_gc: dict[str, float] = {}
    args = list(document.get("game_controller_extra_args", ()))
    index = 0
    while index < len(args):
        arg = args[index]
        at = pointer("game_controller_extra_args", index)
        option, _, inline = arg.partition("=")
        if option not in _GC_DURATION_OPTIONS:
            where.warn(at, f'GameController argument "{arg}" is ignored')
            index += 1
            continue
        if inline:
            value = inline
        elif index + 1 < len(args):
            value = args[index + 1]
            index += 1
            at = pointer("game_controller_extra_args", index)
        else:
            where.error(at, f"{option} without a value", expected="a number of seconds after it")
            break
        try:
            seconds = float(value)
        except ValueError:
            seconds = -1.0
        if not seconds > 0 or seconds == float("inf"):
            where.error(at, f'invalid duration "{value}" for {option}', expected="seconds > 0")
        else:
            from_gc[_GC_DURATION_OPTIONS[option]] = seconds
        index += 1
    for name, seconds in from_gc.items():
        if name in written and float(written[name]) != seconds:
            where.error(
                pointer("timing", name),
                f"{written[name]} conflicts with {seconds:g} from game_controller_extra_args",
                expected="one value",
            )
        written[name] = seconds
    durations: dict[str, float] = {k: float(v) for k, v in written.items()}
    max_duration = document.get("max_duration")
    timing = Timing(
        **durations, max_duration_s=float(max_duration) if max_duration is not None else None
    )
    _check_play_time(timing, document.get("type"), where)
    return timing


def _check_play_time(timing: Timing, game_type: Any, where: Collector) -> None:
    """A half shorter than the minimum of play is refused (:mod:`contracts.timing`): the match
    would end without football. READY and SET do not count: the clock stands still in them
    before each half's kick-off, so a half of 20 s with the rules' 45 s READY plays 20 s."""
    halves = [("half_duration_s", timing.half_duration_s, "half")]
    if game_type == "KNOCKOUT":
        halves.append(("overtime_half_duration_s", timing.overtime_half_duration_s,
                       "half of extra time"))
    for name, seconds, what in halves:
        problem = timing_problem(seconds, what=what, minimum_s=timing.minimum_play_s)
        if problem is not None:
            where.error(pointer("timing", name), problem,
                        expected=f"minimum_play_s ({timing.minimum_play_s:g} s) <= {name}")


def _limits(raw: dict[str, float]) -> Limits:
    values: dict[str, Any] = {
        k: (int(v) if k == "pids" else str(v) if k == "robot_runtime" else float(v))
        for k, v in raw.items()
    }
    return Limits(**values)


def _check_physics_dt(document: GameDocument, where: Collector) -> None:
    dt = float(document.get("physics_dt_s", 0.002))
    substeps = round(BASIC_TIME_STEP_S / dt)
    if substeps < 1 or abs(substeps * dt - BASIC_TIME_STEP_S) > 1e-9:
        where.error(
            "/physics_dt_s",
            f"{dt:g} s does not divide the 8 ms basic time step",
            expected="0.008 / n, e.g. 0.002 or 0.004",
        )


def _check_record(document: GameDocument, where: Collector) -> None:
    record = document.get("record_simulation")
    if isinstance(record, str) and record.endswith(".html"):
        where.warn(
            "/record_simulation",
            "HTML animations are not produced (the replay file is always written)",
            expected="a path ending in .mp4 for a movie",
        )


def _check_team_ids(document: GameDocument, where: Collector) -> None:
    red_id, blue_id = team_id(document["red"]["id"]), team_id(document["blue"]["id"])
    if red_id == blue_id:
        where.error("/blue/id", f"team id {blue_id} is also the red team's id", expected="two ids")
    for color in COLORS:
        if isinstance(document[color]["id"], str):
            where.warn(
                pointer(color, "id"), "a string: converted to a number", expected="an integer"
            )


# Ports the simulator container listens on besides the robot API ports.
SIMULATOR_PORTS = {
    3737: "the team mirror (UDP)",
    3838: "the GameController's data port (UDP)",
    3939: "the GameController's return port (UDP)",
    7447: "telemetry (zenoh)",
}


def _check_ports(document: GameDocument, where: Collector) -> None:
    used: dict[int, str] = {}
    for color in COLORS:
        for index, port in enumerate(document[color]["ports"]):
            at = pointer(color, "ports", index)
            if port in SIMULATOR_PORTS:
                where.error(
                    at, f"port {port} is the simulator's port for {SIMULATOR_PORTS[port]}",
                    expected="a port other than " + ", ".join(map(str, sorted(SIMULATOR_PORTS))),
                )
            elif port in used:
                where.error(
                    at, f"port {port} is already used at {used[port]}", expected="a free port"
                )
            else:
                used[port] = at


def locate_team_config(
    config: str, base: Path, *, cwd: Path | None = None
) -> tuple[Path, tuple[Path, ...]]:
    """The team file a game.json ``config`` names, and every place looked at.

    A relative path is looked up next to the game file first, then in the current working
    directory (the league's referee resolves it from its own folder). Returns the first existing
    file, or the first place when none exists, with all the places tried in order.
    """
    written = Path(config).expanduser()
    if written.is_absolute():
        return written, (written,)
    here = Path(os.path.abspath(cwd if cwd is not None else Path.cwd()))
    tried = tuple(dict.fromkeys(Path(os.path.abspath(b / written)) for b in (base, here)))
    found = next((p for p in tried if p.is_file()), tried[0])
    return found, tried


def _team_ref(color: Color, raw: GameTeamDocument, base: Path, where: Collector) -> TeamRef:
    config, _ = locate_team_config(raw["config"], base)
    return TeamRef(
        color=color,
        team_id=team_id(raw["id"]),
        config=config,
        hosts=tuple(raw["hosts"]),
        ports=tuple(raw["ports"]),
        credentials=_existing(raw.get("credentials"), base, pointer(color, "credentials"), where),
    )


def _existing(raw: str | None, base: Path, at: str, where: Collector) -> Path | None:
    if raw is None:
        return None
    path = base / raw
    if not path.is_file():
        where.error(at, f"file not found: {path}", expected="a path relative to this file")
    return path
