"""The service's settings: one frozen object, read from ``HLVS_SERVICE_*`` environment variables.

Every default lives here. ``Settings.from_env()`` is called by the entrypoint (``hlvs serve``,
``hlvs admin``) only; tests build ``Settings(...)`` directly.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from contracts import TEST_MATCH, TimingError, fit_ready
from service.errors import SettingsError

if TYPE_CHECKING:
    from sqlalchemy import Engine

    from orchestrator.delivery import IPNetwork

PREFIX = "HLVS_SERVICE_"
WEBHOOK_ALLOW_SETTING = PREFIX + "WEBHOOK_ALLOW"
LOG_TARGET_ALLOW_SETTING = PREFIX + "LOG_TARGET_ALLOW"


@dataclass(frozen=True, slots=True, kw_only=True)
class Settings:
    """Typed settings of ``hlvs serve``; environment variable = ``HLVS_SERVICE_`` + upper name."""

    data_dir: Path = Path("service-data")
    """Team files, match folders and the default SQLite database live here."""
    database_url: str = ""
    """SQLAlchemy URL; empty: ``sqlite:///<data_dir>/service.sqlite``. PostgreSQL:
    ``postgresql+psycopg://user:password@host/db``."""
    max_upload_bytes: int = 1_000_000
    keep_alive_s: float = 30.0
    """Idle HTTP connections stay open this long (pollers reuse theirs; a short value races
    with clients that send just as the server closes)."""
    threads: int = 8
    """Threads that run request handlers (database work); more mostly contend for the GIL."""
    token_cache_s: float = 5.0
    """A verified token is trusted this long without a query (a revocation takes this long)."""
    status_board_s: float = 2.0
    """Queue positions of other teams' submissions may lag a change by this long (the status
    of the submission that changed is current at once)."""
    token_days: float = 90.0
    """Lifetime of a newly issued token (``hlvs admin token issue --days`` overrides)."""
    match_slots: int = 1
    """Test matches played at the same time by the pool."""
    stub_image: str = ""
    """Image of the stub opponent; empty: the project's stub image (built when missing)."""
    pool: str = "local"
    """``local``: the Docker engine of this host; ``slurm``: the Slurm cluster (each team's
    test matches run under its own account, see :mod:`service.accounts`)."""
    slurm_conf: str = ""
    """The cluster's slurm.conf (empty: ``SLURM_CONF`` or Slurm's default)."""
    slurm_max_queued: int = 5
    """``MaxSubmitJobs`` of each team's Slurm account (its ``GrpJobs`` is 1)."""
    placement: str = "dense"
    """With the Slurm pool: ``dense``, a whole match on one node; ``league``, the simulator on a
    node and each robot on a node of its own (docs/slurm.md)."""
    worker_poll_s: float = 1.0
    test_half_duration_s: float = TEST_MATCH.half_duration_s
    test_ready_duration_s: float = TEST_MATCH.ready_duration_s
    """READY of a test match (:mod:`contracts.timing`). Before each half's kick-off the
    GameController's clock stands still in it, so it adds to the match's length and takes
    nothing from the half."""
    test_players: int = 1
    test_grace_s: float = TEST_MATCH.grace_period_s
    expected_match_s: float = 120.0
    """Assumed wall time of one test match until some have finished (for expected starts)."""
    video: bool = True
    """Render a video of every test match that played (after it ended, by ``hlvs render``);
    a failed render leaves the match's outcome as it was."""
    video_width: int = 1280
    video_height: int = 720
    video_fps: float = 25.0
    video_timeout_s: float = 1800.0
    """A render still running after this long is stopped and its video marked failed."""
    preflight: str = "full"
    """``full``: pull, size, start and connect to a simulator; ``images``: pull and size only."""
    preflight_timeout_s: float = 25.0
    team_project_images: bool = False
    """Let a team's file name the project's own ``hlvs-runner/*`` images (the stub) as its
    robots: for the project's tests and demonstrations on one machine only; a league leaves it
    off, and the pre-flight refuses them."""
    smtp_host: str = ""
    """Empty: no mail is sent."""
    smtp_port: int = 25
    mail_from: str = "hlvs@localhost"
    webhook_attempts: int = 5
    webhook_backoff_s: float = 2.0
    webhook_timeout_s: float = 5.0
    webhook_allow: str = ""
    """Networks a webhook may reach besides public addresses, comma-separated CIDRs (e.g.
    ``10.20.0.0/16``); empty: public addresses only (no loopback, private, link-local)."""
    log_target_allow: str = ""
    """Networks a team's log target (SFTP ``hostname``, S3 ``endpoint_url``) may reach besides
    public addresses, comma-separated CIDRs; empty: public addresses only. For a league's own
    log server, or a test server on loopback (``127.0.0.0/8``)."""
    secret_key: str = field(default="", repr=False)
    """The key that seals the secrets stored in the database (a Fernet key); empty: the key
    file."""
    secret_key_file: str = ""
    """Where the key is kept when ``secret_key`` is empty; empty: ``<data_dir>.key``, beside
    the data folder (created 0600 on the first start)."""
    public_url: str = "http://127.0.0.1:8000"
    """Base of the links in mails and webhooks."""
    schedule_state: str = ""
    """The tournament's state file (``hlvs schedule run --state``), served to operators; its
    played matches also count for the ladder's ratings."""
    ladder_every_s: float = 0.0
    """The ladder schedules a friendly between two teams that accept them at most this often,
    in a free slot (nothing queued); 0: off (friendlies are still rated)."""
    extra: Mapping[str, str] = field(default_factory=dict)

    @property
    def db_url(self) -> str:
        if self.database_url:
            return self.database_url
        return f"sqlite:///{(self.data_dir / 'service.sqlite').resolve()}"

    @property
    def matches_dir(self) -> Path:
        return self.data_dir / "matches"

    def with_(self, **changes: Any) -> Settings:
        return replace(self, **changes)

    @classmethod
    def from_env(cls, environ: Mapping[str, str] | None = None) -> Settings:
        environ = os.environ if environ is None else environ
        values: dict[str, Any] = {}
        defaults = cls()
        for f in fields(cls):
            if f.name == "extra":
                continue
            name = PREFIX + f.name.upper()
            if name not in environ:
                continue
            raw = environ[name]
            current = getattr(defaults, f.name)
            values[f.name] = _convert(name, raw, current)
        settings = cls(**values)
        _check(settings)
        return settings


def webhook_networks(settings: Settings) -> tuple[IPNetwork, ...]:
    """The networks of ``webhook_allow``; ValueError for one that is not a network."""
    from orchestrator.delivery import networks  # not while the command line builds its parser

    return networks(settings.webhook_allow)


def open_data_dir(settings: Settings) -> Path:
    """The service's data folder (and its matches folder), created 0700 if missing; one that
    cannot be made or written is a :class:`SettingsError` naming ``HLVS_SERVICE_DATA_DIR`` and
    the system's reason."""
    from orchestrator import file_in_the_way, private_dir

    try:
        private_dir(settings.data_dir)
        private_dir(settings.matches_dir)
    except OSError as exc:
        in_the_way = file_in_the_way(exc)
        if in_the_way is not None:
            reason = f"{in_the_way} is a file, not a folder"
        else:
            reason = f"{exc.strerror or exc}" + (f" ({exc.filename})" if exc.filename else "")
        raise SettingsError(
            name=PREFIX + "DATA_DIR", value=str(settings.data_dir),
            expected=f"a folder the service can create and write: {reason}",
        ) from exc
    return settings.data_dir


def open_database(settings: Settings) -> Engine:
    """The service's database (``db_url``), migrated to the newest schema; one that cannot be
    reached is a :class:`SettingsError` naming the URL (its password hidden) and the driver's
    reason: one line for the operator rather than the driver's traceback."""
    from sqlalchemy.engine import make_url
    from sqlalchemy.exc import InterfaceError, OperationalError

    from service.db import make_engine, migrate

    url = settings.db_url
    engine = make_engine(url)
    try:
        migrate(engine)
    except (OperationalError, InterfaceError) as exc:  # no connection (a query's error is not)
        engine.dispose()
        text = str(exc.orig).strip()
        reason = text.splitlines()[0] if text else type(exc.orig).__name__
        raise SettingsError(
            name=PREFIX + "DATABASE_URL",
            value=make_url(url).render_as_string(hide_password=True),
            expected=f"a database that answers ({reason})",
        ) from exc
    return engine


def log_target_networks(settings: Settings) -> tuple[IPNetwork, ...]:
    """The networks of ``log_target_allow``; ValueError for one that is not a network."""
    from orchestrator.delivery import networks

    return networks(settings.log_target_allow)


def _convert(name: str, raw: str, current: object) -> object:
    try:
        if isinstance(current, bool):
            if raw.lower() not in ("1", "0", "true", "false", "yes", "no"):
                raise ValueError(raw)
            return raw.lower() in ("1", "true", "yes")
        if isinstance(current, int):
            return int(raw)
        if isinstance(current, float):
            return float(raw)
        if isinstance(current, Path):
            return Path(raw)
    except ValueError:
        raise SettingsError(name=name, value=raw,
                            expected=f"a {type(current).__name__}") from None
    return raw


def _check(settings: Settings) -> None:
    if settings.pool not in ("local", "slurm"):
        raise SettingsError(name=PREFIX + "POOL", value=settings.pool, expected="local or slurm")
    if settings.placement not in ("dense", "league"):
        raise SettingsError(name=PREFIX + "PLACEMENT", value=settings.placement,
                            expected="dense or league")
    if settings.placement == "league" and settings.pool != "slurm":
        raise SettingsError(name=PREFIX + "PLACEMENT", value=settings.placement,
                            expected=f"dense, or {PREFIX}POOL=slurm (a node per robot)")
    if settings.preflight not in ("full", "images"):
        raise SettingsError(name=PREFIX + "PREFLIGHT", value=settings.preflight,
                            expected="full or images")
    for name in ("video_width", "video_height", "video_fps", "video_timeout_s"):
        if getattr(settings, name) <= 0:
            raise SettingsError(name=PREFIX + name.upper(), value=str(getattr(settings, name)),
                                expected="a positive number")
    from orchestrator.delivery import networks

    for name in ("webhook_allow", "log_target_allow"):
        try:
            networks(getattr(settings, name))
        except ValueError as exc:
            raise SettingsError(name=PREFIX + name.upper(), value=getattr(settings, name),
                                expected=f"comma-separated networks, e.g. 10.0.0.0/8 ({exc})"
                                ) from None
    if settings.ladder_every_s < 0:
        raise SettingsError(name=PREFIX + "LADDER_EVERY_S", value=str(settings.ladder_every_s),
                            expected="0 (off) or a positive number of seconds")
    if not 1 <= settings.test_players <= 4:
        raise SettingsError(name=PREFIX + "TEST_PLAYERS", value=str(settings.test_players),
                            expected="1 to 4 robots a side (both sides field this many)")
    for name in ("threads", "slurm_max_queued", "webhook_attempts"):
        if getattr(settings, name) < 1:
            raise SettingsError(name=PREFIX + name.upper(), value=str(getattr(settings, name)),
                                expected="at least 1")
    for name in ("worker_poll_s", "preflight_timeout_s", "webhook_timeout_s",
                 "expected_match_s", "keep_alive_s", "token_days"):
        if not 0 < getattr(settings, name) < 1e9:
            raise SettingsError(name=PREFIX + name.upper(), value=str(getattr(settings, name)),
                                expected="a positive number of seconds (days for TOKEN_DAYS)")
    if settings.match_slots < 1:
        raise SettingsError(name=PREFIX + "MATCH_SLOTS", value=str(settings.match_slots),
                            expected="at least 1")
    try:
        fit_ready(settings.test_half_duration_s, settings.test_ready_duration_s)
    except TimingError as exc:
        raise SettingsError(name=PREFIX + "TEST_HALF_DURATION_S",
                            value=f"{settings.test_half_duration_s:g}",
                            expected=f"a longer half: {exc}") from None


__all__ = ["LOG_TARGET_ALLOW_SETTING", "Settings", "WEBHOOK_ALLOW_SETTING",
           "log_target_networks", "open_data_dir", "open_database", "webhook_networks"]
