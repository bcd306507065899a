"""``hlvs check SCHEDULE``: everything a tournament's matches will need, in one pass.

Beyond :func:`orchestrator.config.schedule.load_schedule` (schema and cross-references), this
opens every team file (as a match does: images named, poses for the classes the team plays),
every credentials file, and the game.json each kind of match will get from ``game_defaults``
(its schema and rules, and a timing in which READY + SET fit in a half). A schema error does not
hide the other checks: they run on the parts of the file that are sound.
"""

from __future__ import annotations

import logging
from dataclasses import replace
from datetime import UTC, datetime, timedelta
from pathlib import Path
from typing import Any, cast

from orchestrator.config.documents import ScheduleDocument
from orchestrator.config.schedule import (
    Schedule,
    ScheduledMatch,
    ScheduledTeam,
    Slot,
    _cross_problems,
    _read,
    _schema_problems,
    _slot,
    game_document,
    knockout_fixtures,
    resolve_time,
    round_robin_fixtures,
)
from orchestrator.errors import ConfigError, Problem

log = logging.getLogger(__name__)


def check_schedule(path: str | Path, *, now: datetime | None = None) -> list[Problem]:
    """Every problem (errors and warnings) of a schedule and of the files its matches use.

    ``now``: refuse matches whose stream starts before it (``hlvs check`` and the first ``hlvs
    schedule run``; not ``hlvs schedule apply``, where the day's earlier matches are past)."""
    path = Path(path)
    try:
        data = _read(path)
    except ConfigError as exc:
        return list(exc.problems)
    problems = _schema_problems(path, data)
    if not isinstance(data, dict):
        return problems
    schedule = _lenient(path, data)
    broken = [p.pointer for p in problems]
    try:
        problems += [
            # the parts the schema rejected raise below (and stop the cross-checks)
            p for p in _cross_problems(
                path, schedule, cast("ScheduleDocument", _sound_fixtures(data))
            )
            if not any(p.pointer == b or p.pointer.startswith(b + "/") for b in broken)
        ]
    except (KeyError, TypeError, AttributeError, ValueError):  # a part the schema rejected
        log.debug("cross-checks of %s stopped early", path, exc_info=True)
    problems += _timing_problems(path, schedule)
    problems += _plan_problems(path, schedule, data, now)
    problems += _team_problems(schedule)
    problems += _credentials_problems(schedule)
    problems += _game_problems(path, schedule)
    return _unique(problems)


def _unique(problems: list[Problem]) -> list[Problem]:
    seen: set[tuple[str, str, str]] = set()
    out = []
    for problem in problems:
        key = (problem.file, problem.pointer, problem.message)
        if key not in seen:
            seen.add(key)
            out.append(problem)
    return out


def _sound_fixtures(data: dict[str, Any]) -> dict[str, Any]:
    fixtures = data.get("fixtures")
    if not isinstance(fixtures, dict):
        return {**data, "fixtures": {}}
    sound = {k: v for k, v in fixtures.items() if _fixture_ok(k, v)}
    return {**data, "fixtures": sound}


def _fixture_ok(kind: str, spec: Any) -> bool:
    names = "teams" if kind == "round_robin" else "seeds"
    return (
        isinstance(spec, dict)
        and isinstance(spec.get(names), list)
        and all(isinstance(n, str) for n in spec[names])
        and isinstance(spec.get("first_stream"), str)
        and all(isinstance(spec.get(k, 1), int | float) for k in ("interval_s", "stream_length_s"))
    )


def _lenient(path: Path, data: dict[str, Any]) -> Schedule:
    """The schedule built from the parts of ``data`` that can be read (others left out)."""
    base = path.resolve().parent
    teams = []
    for i, team in enumerate(data.get("teams") or []):
        if not isinstance(team, dict) or not isinstance(team.get("name"), str):
            continue
        team_id = team.get("id")
        config = team.get("config")
        credentials = team.get("credentials")
        teams.append(ScheduledTeam(
            name=team["name"],
            team_id=team_id if isinstance(team_id, int) else -1 - i,
            config=(base / config).resolve() if isinstance(config, str) else base / "",
            credentials=(base / credentials).resolve() if isinstance(credentials, str) else None,
        ))
    matches: list[ScheduledMatch] = []
    for i, match in enumerate(data.get("matches") or []):
        try:
            matches.append(_lenient_match(match))
        except (KeyError, TypeError, ValueError, AttributeError):  # keeps the indexes
            matches.append(ScheduledMatch(id=f"(match {i})", red=Slot(), blue=Slot(),
                                          field_class="KID", kind="round_robin",
                                          stream_start="+0s", stream_length_s=1.0))
    fixtures = _sound_fixtures(data)["fixtures"]
    if "round_robin" in fixtures:
        matches += round_robin_fixtures(fixtures["round_robin"])
    if "knockout" in fixtures:
        matches += knockout_fixtures(fixtures["knockout"])
    defaults = data.get("game_defaults")
    public = data.get("public_logs")
    return Schedule(
        source=path.resolve(),
        name=str(data.get("name", "")),
        start=None,
        output_dir=base,
        log_store=base,
        public_logs=(base / public).resolve() if isinstance(public, str) else None,
        simulator_slots=1,
        timing=_lenient_timing(data.get("timing")),
        game_defaults=dict(defaults) if isinstance(defaults, dict) else {},
        teams=tuple(teams),
        matches=tuple(matches),
    )


def _lenient_match(m: dict[str, Any]) -> ScheduledMatch:
    for side in ("red", "blue"):
        if not isinstance(m[side], str | dict):
            raise TypeError(side)
    kind = m.get("kind", "round_robin")
    field_class = m.get("class", "KID")
    return ScheduledMatch(
        id=str(m["id"]),
        red=_slot(m["red"]),
        blue=_slot(m["blue"]),
        field_class=field_class if field_class in ("KID", "ADULT") else "KID",
        kind=kind if kind in ("round_robin", "knockout", "friendly") else "round_robin",
        stream_start=str(m["stream_start"]),
        stream_length_s=float(m.get("stream_length_s", 1800.0)),
    )


def _lenient_timing(data: Any) -> Any:
    from orchestrator.config.schedule import ScheduleTiming

    timing = ScheduleTiming()
    if not isinstance(data, dict):
        return timing
    for key, value in data.items():
        if key in ScheduleTiming.__dataclass_fields__ and isinstance(value, int | float):
            timing = replace(timing, **{key: type(getattr(timing, key))(value)})
    return timing


def _timing_problems(path: Path, schedule: Schedule) -> list[Problem]:
    problems = []
    timing = schedule.timing
    for kind, name in (("round_robin", "pull_lead_round_robin_s"),
                       ("knockout", "pull_lead_knockout_s")):
        if not any((m.kind == "knockout") == (kind == "knockout") for m in schedule.matches):
            continue  # friendly matches are pulled as round-robin ones
        if timing.play_after_pull_s >= timing.pull_lead_s(kind):  # type: ignore[arg-type]
            problems.append(Problem(
                str(path), "/timing/play_after_pull_s",
                f"{timing.play_after_pull_s:g} s after the pull is not before the stream "
                f"({name} {timing.pull_lead_s(kind):g} s): {kind} matches are played at the "  # type: ignore[arg-type]
                "stream's start, with no margin",
                expected=f"less than {name}", severity="warning"))
    return problems


def _plan_problems(path: Path, schedule: Schedule, data: dict[str, Any],
                   now: datetime | None) -> list[Problem]:
    """What would go wrong on the day: a team whose logs have nowhere to go, a match whose
    stream has started (with ``now``), two streams of one team at once, fixtures whose streams
    overlap (an interval shorter than a stream)."""
    file = str(path)
    problems = []
    for i, team in enumerate(schedule.teams):
        if team.credentials is None:
            problems.append(Problem(
                file, f"/teams/{i}/credentials", f"team {team.name!r} has no log target: its "
                "logs would wait in the log store after every match",
                expected="credentials: the team's credentials.json (SFTP or S3)"))
    fixtures = _sound_fixtures(data)["fixtures"]
    for kind, spec in fixtures.items():
        interval = float(spec.get("interval_s", 3600.0))
        length = float(spec.get("stream_length_s", 1800.0))
        if interval < length:
            problems.append(Problem(
                file, f"/fixtures/{kind}/interval_s", f"{interval:g} s between two streams is "
                f"shorter than a stream ({length:g} s): streams would overlap",
                expected=f"at least stream_length_s ({length:g})"))
    start = data.get("start")
    reference = datetime.now(UTC)
    try:
        if isinstance(start, str) and start != "now":
            reference = resolve_time(start, reference)
    except ValueError:
        return problems  # reported by the cross-checks
    listed = len(data.get("matches") or [])
    streams: list[tuple[datetime, datetime, ScheduledMatch, str]] = []
    for i, match in enumerate(schedule.matches):
        pointer = f"/matches/{i}" if i < listed else f"(fixture {match.id})"
        try:
            begin = resolve_time(match.stream_start, reference)
        except ValueError:
            continue  # reported by the cross-checks
        if now is not None and begin <= now:
            problems.append(Problem(
                file, f"{pointer}/stream_start", f"match {match.id}: its stream starts "
                f"{begin.isoformat(timespec='seconds')}, in the past",
                expected="a time after now (or an offset from start: now)"))
        streams.append((begin, begin + timedelta(seconds=match.stream_length_s), match,
                        pointer))
    for k, (begin, end, match, pointer) in enumerate(streams):
        teams = {t for t in (match.red.team, match.blue.team) if t is not None}
        for other_begin, other_end, other, _ in streams[:k]:
            both = teams & {t for t in (other.red.team, other.blue.team) if t is not None}
            if both and begin < other_end and other_begin < end:
                problems.append(Problem(
                    file, f"{pointer}/stream_start", f"match {match.id}: {sorted(both)[0]!r} "
                    f"also plays {other.id}, whose stream "
                    f"({other_begin.isoformat(timespec='minutes')} for "
                    f"{(other_end - other_begin).total_seconds():g} s) overlaps this one",
                    expected="streams of one team one after the other"))
    return problems


def _classes_of(schedule: Schedule, team: str) -> set[str]:
    """The field classes of the matches ``team`` may play (knockout slots: any later round)."""
    named = [m for m in schedule.matches if team in (m.red.team, m.blue.team)]
    classes: set[str] = {m.field_class for m in named}
    if any(m.kind == "knockout" for m in named):
        classes |= {m.field_class for m in schedule.matches if m.kind == "knockout"}
    return classes


def _team_problems(schedule: Schedule) -> list[Problem]:
    from contracts import FieldClass
    from orchestrator.config.loader import check_team

    problems: list[Problem] = []
    official = schedule.game_defaults.get("official") is True  # as each match's game.json says
    for team in schedule.teams:
        if not team.config.is_file():
            continue  # reported by the cross-checks
        classes: list[str | None] = [*sorted(_classes_of(schedule, team.name))] or [None]
        for field_class in classes:
            problems += check_team(  # the schedule says KID / ADULT, as game.json does
                team.config, field_class=FieldClass(field_class.lower()) if field_class else None,
                images_required=True, official=official)
    return problems


def _credentials_problems(schedule: Schedule) -> list[Problem]:
    from orchestrator.config.credentials import load_credentials

    files = [t.credentials for t in schedule.teams if t.credentials is not None]
    if schedule.public_logs is not None:
        files.append(schedule.public_logs)
    problems: list[Problem] = []
    loader_log = logging.getLogger("orchestrator.config.credentials")
    level = loader_log.level
    loader_log.setLevel(logging.ERROR)  # its warnings are returned with the other problems
    try:
        for path in dict.fromkeys(files):
            if not path.is_file():
                continue  # reported by the cross-checks
            try:
                loaded = load_credentials(path)
            except ConfigError as exc:
                problems += exc.problems
                continue
            problems += [w for w in getattr(loaded, "warnings", ()) if isinstance(w, Problem)]
    finally:
        loader_log.setLevel(level)
    return problems


def _game_problems(path: Path, schedule: Schedule) -> list[Problem]:
    """The game.json of each kind of match (class, knockout or not), checked as a match would
    check it; problems in the defaults point into ``/game_defaults``."""
    from orchestrator.config.game import build_game
    from orchestrator.config.problems import Collector
    from orchestrator.config.timing_rules import timing_problems

    if len(schedule.teams) < 2:
        return []
    red, blue = schedule.teams[0], schedule.teams[1]
    kinds = {(m.field_class, m.kind): m for m in schedule.matches}
    if not kinds:
        kinds = {("KID", "round_robin"): ScheduledMatch(
            id="check", red=_slot(red.name), blue=_slot(blue.name), field_class="KID",
            kind="round_robin", stream_start="+0s", stream_length_s=1.0)}
    problems: list[Problem] = []
    for (field_class, kind), match in sorted(kinds.items()):
        document = game_document(schedule, match, replace(red, credentials=None),
                                 replace(blue, credentials=None))  # checked on their own
        where = Collector(str(path))
        game = build_game(document, where, source=path)
        for problem in where.problems:
            top = problem.pointer.split("/")[1] if problem.pointer.count("/") else ""
            if top in schedule.game_defaults:
                problems.append(replace(problem, pointer="/game_defaults" + problem.pointer))
            elif top not in ("red", "blue"):  # the teams' sides are the schedule's own
                problems.append(replace(
                    problem, message=f"{problem.message} (in the game.json of {field_class} "
                    f"{kind} matches)"))
        if game is not None:
            for name, message, expected in timing_problems(game.timing,
                                                           knockout=kind == "knockout"):
                problems.append(Problem(str(path), f"/game_defaults/timing/{name}", message,
                                        expected=expected))
    return problems
