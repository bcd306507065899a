"""Tournament schedule files (YAML or JSON): teams, matches or fixtures, timing, simulator slots.

``load_schedule(path)`` validates the file against ``schemas/schedule.schema.json`` and the
cross-references (team names, match ids, bracket size) and returns a frozen :class:`Schedule`.
Stream times may be absolute (ISO 8601 with a time zone) or offsets from ``start`` (``+90s``,
``+15m``, ``+2h``); :meth:`Schedule.plan` turns them into absolute times once the tournament's
reference time is known (``start: now`` is fixed at the first run and kept in the state file).
"""

from __future__ import annotations

import difflib
import hashlib
import json
import re
from dataclasses import dataclass
from datetime import UTC, datetime, timedelta
from importlib import resources
from pathlib import Path
from typing import Any, Literal, cast

import jsonschema
import yaml

from contracts import HugeInteger, JSONObject
from orchestrator.config.documents import (
    GameDocument,
    KnockoutDocument,
    RoundRobinDocument,
    ScheduleDocument,
    ScheduleMatchDocument,
)
from orchestrator.config.game import default_real_time_factor
from orchestrator.config.jsonfile import huge_integer_problems
from orchestrator.errors import ConfigError, Problem

MatchKind = Literal["round_robin", "knockout", "friendly"]
"""round_robin: counts in the standings; knockout: a KNOCKOUT game (extra time, shoot-out);
friendly: a NORMAL game that counts nowhere."""
_OFFSET = re.compile(r"^\+(\d+(?:\.\d+)?)([smhd])$")
_UNIT_S = {"s": 1.0, "m": 60.0, "h": 3600.0, "d": 86400.0}


@dataclass(frozen=True, slots=True, kw_only=True)
class ScheduleTiming:
    pull_lead_round_robin_s: float = 4 * 3600.0
    pull_lead_knockout_s: float = 7 * 3600.0
    play_after_pull_s: float = 600.0
    deliver_after_stream_s: float = 0.0
    retry_s: float = 300.0
    delivery_attempts: int = 3

    def pull_lead_s(self, kind: MatchKind) -> float:
        return self.pull_lead_knockout_s if kind == "knockout" else self.pull_lead_round_robin_s


@dataclass(frozen=True, slots=True, kw_only=True)
class SchedulePool:
    """Where the tournament's matches run: this host's Docker engine (``local``) or one Slurm
    job per match on a whole node of a cluster (``slurm``; ``slurm_conf`` names the cluster,
    ``account`` the Slurm account the matches are charged to; ``placement`` ``league`` puts
    the simulator and each robot on nodes of their own)."""

    kind: Literal["local", "slurm"] = "local"
    slurm_conf: str | None = None
    account: str | None = None
    placement: Literal["dense", "league"] = "dense"


@dataclass(frozen=True, slots=True, kw_only=True)
class ScheduledTeam:
    name: str
    team_id: int
    config: Path
    credentials: Path | None = None


@dataclass(frozen=True, slots=True)
class Slot:
    """A side of a match: a team name, or the winner / loser of an earlier match."""

    team: str | None = None
    winner_of: str | None = None
    loser_of: str | None = None

    def __str__(self) -> str:
        if self.team is not None:
            return self.team
        return f"winner of {self.winner_of}" if self.winner_of else f"loser of {self.loser_of}"


@dataclass(frozen=True, slots=True, kw_only=True)
class ScheduledMatch:
    id: str
    red: Slot
    blue: Slot
    field_class: Literal["KID", "ADULT"]
    kind: MatchKind
    stream_start: str  # ISO 8601 or "+<n><unit>" offset from the schedule's start
    stream_length_s: float


@dataclass(frozen=True, slots=True, kw_only=True)
class PlannedMatch:
    """A match with absolute times (UTC)."""

    match: ScheduledMatch
    pull_at: datetime
    play_at: datetime
    stream_start: datetime
    stream_end: datetime
    deliver_at: datetime


@dataclass(frozen=True, slots=True, kw_only=True)
class Schedule:
    source: Path
    name: str
    start: str | None
    output_dir: Path
    log_store: Path
    public_logs: Path | None
    simulator_slots: int
    timing: ScheduleTiming
    game_defaults: JSONObject  # game.json fields every match gets (checked with its game.json)
    teams: tuple[ScheduledTeam, ...]
    matches: tuple[ScheduledMatch, ...]
    pool: SchedulePool = SchedulePool()

    def team(self, name: str) -> ScheduledTeam:
        for team in self.teams:
            if team.name == name:
                return team
        raise KeyError(name)

    def match(self, match_id: str) -> ScheduledMatch:
        for match in self.matches:
            if match.id == match_id:
                return match
        raise KeyError(match_id)

    def league_match_id(self, match_id: str) -> str:
        """The match's id outside the tournament (its game.json, containers, Slurm job, log
        sets and the folders the teams receive): the tournament's name, then the match's id
        (``example-cup-rr-1``), so two tournaments on one host or one team's log server never
        meet on ``rr-1``. At most 64 characters, as game.json's ``match_id``."""
        slug = name_slug(self.name)
        text = f"{slug}-{match_id}" if slug else match_id
        if len(text) > 64 or not re.match(r"^[A-Za-z0-9]", text):
            digest = hashlib.sha256(text.encode()).hexdigest()[:8]
            text = f"m{digest}-{match_id}"[:64]
        return text

    def plan(self, reference: datetime) -> list[PlannedMatch]:
        """Absolute times of every match, relative offsets counted from ``reference``."""
        planned = []
        for match in self.matches:
            stream_start = resolve_time(match.stream_start, reference)
            pull_at = stream_start - timedelta(seconds=self.timing.pull_lead_s(match.kind))
            play_at = pull_at + timedelta(seconds=self.timing.play_after_pull_s)
            stream_end = stream_start + timedelta(seconds=match.stream_length_s)
            deliver_at = stream_end + timedelta(seconds=self.timing.deliver_after_stream_s)
            planned.append(
                PlannedMatch(
                    match=match,
                    pull_at=pull_at,
                    play_at=min(play_at, stream_start),
                    stream_start=stream_start,
                    stream_end=stream_end,
                    deliver_at=deliver_at,
                )
            )
        return planned


def game_document(
    schedule: Schedule,
    match: ScheduledMatch,
    red: ScheduledTeam,
    blue: ScheduledTeam,
    *,
    game_type: str | None = None,
) -> JSONObject:
    """The game.json of a match: HLVS fields, the schedule's ``game_defaults``, both teams.

    The game type follows the match's kind (NORMAL, or KNOCKOUT: overtime, then a penalty
    shoot-out) and is never taken from the defaults; ``game_type`` PENALTY is a shoot-out only.
    """
    game: JSONObject = {
        "class": match.field_class,
        "host": "127.0.0.1",
        "maximum_real_time_factor": default_real_time_factor(
            str(schedule.game_defaults.get("stepping", "async"))),
        "match_id": schedule.league_match_id(match.id),
    }
    game.update(schedule.game_defaults)
    game["type"] = game_type or ("KNOCKOUT" if match.kind == "knockout" else "NORMAL")
    for color, team, base in (("red", red, 10000), ("blue", blue, 10020)):
        side: JSONObject = {
            "id": team.team_id,
            "config": str(team.config),
            "hosts": ["127.0.0.1"],
            "ports": [base + n for n in range(1, 5 if match.field_class == "KID" else 4)],
        }
        if team.credentials is not None:
            side["credentials"] = str(team.credentials)
        game[color] = side
    return game


def resolve_time(text: str, reference: datetime) -> datetime:
    match = _OFFSET.match(text)
    if match:
        return reference + timedelta(seconds=float(match.group(1)) * _UNIT_S[match.group(2)])
    parsed = datetime.fromisoformat(text)
    if parsed.tzinfo is None:
        raise ValueError(f"time {text!r} has no time zone")
    return parsed.astimezone(UTC)


def _schema() -> JSONObject:
    text = resources.files("orchestrator.config.schemas").joinpath("schedule.schema.json")
    loaded: JSONObject = json.loads(text.read_text(encoding="utf-8"))
    return loaded


def _pointer(parts: Any) -> str:
    return "".join(f"/{p}" for p in parts)


def _read(path: Path, text: str | None = None) -> Any:
    try:
        raw = path.read_bytes() if text is None else text.encode("utf-8")
    except FileNotFoundError:
        raise ConfigError([Problem(str(path), "", "file not found")]) from None
    except OSError as exc:
        raise ConfigError([Problem(str(path), "", f"cannot read: {exc.strerror}")]) from None
    if not raw.strip():
        raise ConfigError([Problem(str(path), "", "empty file", expected="a YAML schedule")])
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise ConfigError(
            [Problem(str(path), "", "not a text file (invalid UTF-8)", expected="a YAML schedule")]
        ) from None
    try:
        data = yaml.load(text, Loader=_Loader)  # noqa: S506 (safe: SafeLoader's constructors)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise ConfigError([Problem(str(path), "", f"invalid YAML{where}: {problem}")]) from None
    huge = huge_integer_problems(data, file=str(path))
    if huge:
        raise ConfigError(huge)
    return data


class _Loader(yaml.SafeLoader):
    """YAML's safe loader, but an integer too long to read is kept as its text
    (:class:`~orchestrator.config.jsonfile.HugeInteger`) to be reported where it is."""


def _construct_int(loader: yaml.SafeLoader, node: yaml.ScalarNode) -> int | HugeInteger:
    try:
        value: int = yaml.SafeLoader.construct_yaml_int(loader, node)
    except ValueError:
        return HugeInteger(str(node.value))
    return value


_Loader.add_constructor("tag:yaml.org,2002:int", _construct_int)


def _schema_problems(path: Path, data: Any) -> list[Problem]:
    validator = jsonschema.Draft202012Validator(_schema())
    problems = []
    for error in sorted(validator.iter_errors(data), key=lambda e: list(e.absolute_path)):
        pointer = _pointer(error.absolute_path)
        suggestion = ""
        if error.validator == "additionalProperties" and isinstance(error.instance, dict):
            allowed = list(error.schema.get("properties", {}))
            extra = [k for k in error.instance if k not in allowed]
            if extra:
                pointer = f"{pointer}/{extra[0]}"
                close = difflib.get_close_matches(str(extra[0]), allowed, n=1)
                suggestion = f'"{close[0]}"' if close else ""
                problems.append(
                    Problem(
                        str(path),
                        pointer,
                        "unknown key",
                        expected=", ".join(allowed),
                        suggestion=suggestion,
                    )
                )
                continue
        problems.append(Problem(str(path), pointer, error.message))
    return problems


def name_slug(name: str) -> str:
    """A tournament's name in lower-case letters, digits and dashes, at most 24 characters
    (``Example Cup`` -> ``example-cup``); empty when the name has none of them."""
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")[:24].strip("-")


def default_output_dir(name: str) -> str:
    """``tournament/<name slug>``, so that two schedule files in one folder that name no
    ``output_dir`` keep their match folders apart (``tournament`` for a name without letters or
    digits)."""
    slug = name_slug(name)
    return f"tournament/{slug}" if slug else "tournament"


def load_schedule(path: str | Path, *, text: str | None = None) -> Schedule:
    """Validate and load a schedule file; raises ConfigError listing every problem.

    ``text``: the file's content as it was recorded (the tournament's state file keeps the
    schedule it runs, so that an edit applies only when the operator says so); relative paths
    are still resolved against ``path``'s folder.
    """
    path = Path(path)
    raw = _read(path, text)
    problems = _schema_problems(path, raw)
    if problems:
        raise ConfigError(problems)
    data = cast("ScheduleDocument", raw)  # the schema checked it
    base = path.resolve().parent
    teams = tuple(
        ScheduledTeam(
            name=t["name"],
            team_id=int(t["id"]),
            config=(base / t["config"]).resolve(),
            credentials=(base / t["credentials"]).resolve() if t.get("credentials") else None,
        )
        for t in data["teams"]
    )
    matches = [_match(m) for m in data.get("matches", [])]
    fixtures = data.get("fixtures", {})
    if "round_robin" in fixtures:
        matches += round_robin_fixtures(fixtures["round_robin"])
    if "knockout" in fixtures:
        matches += knockout_fixtures(fixtures["knockout"])
    output_dir = (base / data.get("output_dir", default_output_dir(data["name"]))).resolve()
    schedule = Schedule(
        source=path.resolve(),
        name=data["name"],
        start=data.get("start"),
        output_dir=output_dir,
        log_store=(base / data["log_store"]).resolve()
        if "log_store" in data
        else output_dir / "log-store",
        public_logs=(base / data["public_logs"]).resolve() if "public_logs" in data else None,
        simulator_slots=int(data.get("simulator_slots", 1)),
        timing=_timing(data.get("timing", {})),
        game_defaults=dict(data.get("game_defaults", {})),
        teams=teams,
        matches=tuple(matches),
        pool=SchedulePool(**data.get("pool", {})),
    )
    problems = _cross_problems(path, schedule, data) + _timing_problems(path, schedule)
    if problems:
        raise ConfigError(problems)
    return schedule


def _timing(data: dict[str, float]) -> ScheduleTiming:
    values: dict[str, Any] = {k: float(v) for k, v in data.items()}
    if "delivery_attempts" in values:
        values["delivery_attempts"] = int(values["delivery_attempts"])
    return ScheduleTiming(**values)


def _timing_problems(path: Path, schedule: Schedule) -> list[Problem]:
    """The game timing every match of the schedule gets (``game_defaults``), checked as a
    game.json's is (:mod:`contracts.timing`): refused here, not when the first match starts."""
    from orchestrator.config.game import timing_of
    from orchestrator.config.problems import Collector

    defaults = schedule.game_defaults
    if not isinstance(defaults.get("timing", {}), dict):
        return []  # the schema reports it
    where = Collector(str(path))
    rtf = defaults.get("maximum_real_time_factor",
                       default_real_time_factor(str(defaults.get("stepping", "async"))))
    for kind in sorted({m.kind for m in schedule.matches}):
        document = {**defaults, "type": "KNOCKOUT" if kind == "knockout" else "NORMAL"}
        # a partial game.json: the timing reads only its timing fields and type
        fast = isinstance(rtf, int | float) and rtf <= 0
        timing_of(cast("GameDocument", document), where, fast=fast)
    seen: set[tuple[str, str]] = set()
    problems = []
    for problem in where.errors:
        if (problem.pointer, problem.message) in seen:
            continue
        seen.add((problem.pointer, problem.message))
        problems.append(Problem(problem.file, "/game_defaults" + problem.pointer,
                                problem.message, expected=problem.expected))
    return problems


def _slot(value: Any) -> Slot:
    if isinstance(value, str):
        return Slot(team=value)
    return Slot(winner_of=value.get("winner_of"), loser_of=value.get("loser_of"))


def _match(m: ScheduleMatchDocument) -> ScheduledMatch:
    return ScheduledMatch(
        id=m["id"],
        red=_slot(m["red"]),
        blue=_slot(m["blue"]),
        field_class=m.get("class", "KID"),
        kind=m.get("kind", "round_robin"),
        stream_start=m["stream_start"],
        stream_length_s=float(m.get("stream_length_s", 1800.0)),
    )


def _stream_time(first: str, index: int, interval_s: float) -> str:
    """The i-th stream start after ``first`` (an offset or an ISO time), in the same style."""
    offset = _OFFSET.match(first)
    if offset:
        seconds = float(offset.group(1)) * _UNIT_S[offset.group(2)] + index * interval_s
        return f"+{seconds:g}s"
    start = datetime.fromisoformat(first)
    return (start + timedelta(seconds=index * interval_s)).isoformat()


def round_robin_fixtures(spec: RoundRobinDocument) -> list[ScheduledMatch]:
    """Every pair once, in rounds (circle method), one stream after another."""
    teams: list[str | None] = list(spec["teams"])
    if len(teams) % 2:
        teams.append(None)  # bye
    n = len(teams)
    pairs: list[tuple[str, str]] = []
    for rnd in range(n - 1):
        for i in range(n // 2):
            a, b = teams[i], teams[n - 1 - i]
            if a is not None and b is not None:
                pairs.append((a, b) if rnd % 2 == 0 else (b, a))
        teams = [teams[0], teams[-1], *teams[1:-1]]
    interval = float(spec.get("interval_s", 3600.0))
    return [
        ScheduledMatch(
            id=f"rr-{k + 1}",
            red=Slot(team=red),
            blue=Slot(team=blue),
            field_class=spec.get("class", "KID"),
            kind="round_robin",
            stream_start=_stream_time(spec["first_stream"], k, interval),
            stream_length_s=float(spec.get("stream_length_s", 1800.0)),
        )
        for k, (red, blue) in enumerate(pairs)
    ]


def knockout_fixtures(spec: KnockoutDocument) -> list[ScheduledMatch]:
    """A single-elimination bracket: seeds paired in order, winners advance to the next round."""
    seeds = list(spec["seeds"])
    interval = float(spec.get("interval_s", 3600.0))
    matches: list[ScheduledMatch] = []
    current: list[Slot] = [Slot(team=s) for s in seeds]
    rnd = 1
    while len(current) > 1:
        nxt: list[Slot] = []
        for i in range(0, len(current), 2):
            match_id = f"ko-r{rnd}-{i // 2 + 1}"
            matches.append(
                ScheduledMatch(
                    id=match_id,
                    red=current[i],
                    blue=current[i + 1],
                    field_class=spec.get("class", "KID"),
                    kind="knockout",
                    stream_start=_stream_time(spec["first_stream"], len(matches), interval),
                    stream_length_s=float(spec.get("stream_length_s", 1800.0)),
                )
            )
            nxt.append(Slot(winner_of=match_id))
        current = nxt
        rnd += 1
    return matches


def _cross_problems(path: Path, schedule: Schedule, data: ScheduleDocument) -> list[Problem]:
    """What the schema cannot see: teams listed twice or their files missing, fixtures naming
    unknown teams, matches naming unknown teams or matches not listed before them."""
    file = str(path)
    names = [t.name for t in schedule.teams]
    return [
        *_team_problems(file, schedule),
        *_fixture_problems(file, data, names),
        *_match_problems(file, schedule, data, names),
    ]


def _team_problems(file: str, schedule: Schedule) -> list[Problem]:
    """Names and ids used twice; team and credentials files not found."""
    problems: list[Problem] = []
    names = [t.name for t in schedule.teams]
    for i, name in enumerate(names):
        if names.index(name) != i:
            problems.append(Problem(file, f"/teams/{i}/name", f"team {name!r} listed twice"))
    ids = [t.team_id for t in schedule.teams]
    for i, team_id in enumerate(ids):
        if ids.index(team_id) != i:
            problems.append(Problem(file, f"/teams/{i}/id", f"team id {team_id} used twice"))
    for i, team in enumerate(schedule.teams):
        if not team.config.is_file():
            problems.append(Problem(file, f"/teams/{i}/config", f"file not found: {team.config}"))
        if team.credentials is not None and not team.credentials.is_file():
            problems.append(
                Problem(file, f"/teams/{i}/credentials", f"file not found: {team.credentials}")
            )
    return problems


def _fixture_problems(file: str, data: ScheduleDocument, names: list[str]) -> list[Problem]:
    """A knockout's seeds not a power of two; fixtures naming teams not in ``names``."""
    problems: list[Problem] = []
    if "knockout" in data.get("fixtures", {}):
        n = len(data["fixtures"]["knockout"]["seeds"])
        if n & (n - 1):
            problems.append(
                Problem(
                    file,
                    "/fixtures/knockout/seeds",
                    f"{n} teams",
                    expected="a power of two (2, 4, 8, ...)",
                )
            )
    fixtures = data.get("fixtures", {})
    for key, field_name, names_listed in (
        ("round_robin", "teams", fixtures.get("round_robin", {}).get("teams", [])),
        ("knockout", "seeds", fixtures.get("knockout", {}).get("seeds", [])),
    ):
        for j, name in enumerate(names_listed):
            if name not in names:
                close = difflib.get_close_matches(name, names, n=1)
                problems.append(
                    Problem(
                        file,
                        f"/fixtures/{key}/{field_name}/{j}",
                        f"unknown team {name!r}",
                        expected="a name from /teams",
                        suggestion=f'"{close[0]}"' if close else "",
                    )
                )
    return problems


def _match_problems(
    file: str, schedule: Schedule, data: ScheduleDocument, names: list[str]
) -> list[Problem]:
    """Each match (listed, then generated from the fixtures): its id used twice, a team not in
    ``names`` or playing itself, a winner or loser of a match not listed before it, a stream
    start that is not a time."""
    problems: list[Problem] = []
    ids_seen: list[str] = []
    listed = len(data.get("matches") or [])
    generated = {m.id for m in schedule.matches[listed:]}  # fixtures: any match may follow them
    reference = datetime(2000, 1, 1, tzinfo=UTC)
    for i, match in enumerate(schedule.matches):
        pointer = f"/matches/{i}" if i < len(data.get("matches", [])) else f"(fixture {match.id})"
        if match.id in ids_seen:
            problems.append(Problem(file, f"{pointer}/id", f"match id {match.id!r} used twice"))
        for color, slot in (("red", match.red), ("blue", match.blue)):
            if slot.team is not None and slot.team not in names:
                close = difflib.get_close_matches(slot.team, names, n=1)
                problems.append(
                    Problem(
                        file,
                        f"{pointer}/{color}",
                        f"unknown team {slot.team!r}",
                        expected="a name from /teams",
                        suggestion=f'"{close[0]}"' if close else "",
                    )
                )
            ref = slot.winner_of or slot.loser_of
            if ref is not None and ref not in ids_seen and ref not in generated:
                problems.append(
                    Problem(
                        file,
                        f"{pointer}/{color}",
                        f"refers to match {ref!r}, which is not listed before it",
                    )
                )
        if match.red.team is not None and match.red.team == match.blue.team:
            problems.append(Problem(file, pointer, f"team {match.red.team!r} plays itself"))
        try:
            resolve_time(match.stream_start, reference)
        except ValueError as exc:
            problems.append(
                Problem(
                    file,
                    f"{pointer}/stream_start",
                    str(exc),
                    expected="ISO 8601 with a time zone or an offset like +90s",
                )
            )
        ids_seen.append(match.id)
    return problems
