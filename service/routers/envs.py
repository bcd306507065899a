"""The HTTP environment API (gym-http-api's routes and JSON bodies), mounted in ``hlvs serve``.

Every route needs a team token (``Authorization: Bearer ...``); a team sees only its own
instances (others answer 404). Environments run in the service's process.

    POST /v1/envs/                          {"env_id", "kwargs"}     -> {"instance_id"}
    GET  /v1/envs/                                                   -> {"all_envs": {id: env_id}}
    POST /v1/envs/<id>/reset/               {"seed"}                 -> {"observation", "info"}
    POST /v1/envs/<id>/step/                {"action"}               -> {"observation", "reward",
                                                   "done", "terminated", "truncated", "info"}
    GET  /v1/envs/<id>/action_space/                                 -> {"info": {...}}
    POST /v1/envs/<id>/monitor/start/       {"force", "resume", "video"}
    POST /v1/envs/<id>/monitor/close/                                -> {"stats"}
    GET  /v1/envs/<id>/monitor/files/                                -> {"files": [{name, bytes}]}
    GET  /v1/envs/<id>/monitor/files/<name>                          -> the file
    POST /v1/envs/<id>/close/

At most ``HLVS_ENVS_PER_TOKEN`` (default 2) environments open per token at a time (409 beyond).
An instance left without a call for ``HLVS_ENVS_IDLE_S`` (default 600 s) is closed when the next
environment is created. A closed instance's monitor files stay downloadable until the service
restarts.
"""

from __future__ import annotations

import logging
import os
import secrets
import shutil
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
from fastapi import APIRouter, FastAPI, Request
from fastapi.responses import FileResponse
from pydantic import BaseModel, Field

from envs import EnvConfigError, EnvError, Monitor
from service.deps import SessionRoute, TeamPrincipal
from service.errors import Conflict, InvalidInput, NotFound

router = APIRouter(prefix="/v1/envs", tags=["envs"], route_class=SessionRoute)

ALLOWED_KWARGS = frozenset({
    "perception", "perception_noise", "steps_per_action", "max_episode_s", "ball_distance_m",
    "half_duration_s", "minimum_play_s", "field_class",
})  # fmt: skip
DEFAULT_PER_TOKEN = 2
DEFAULT_IDLE_S = 600.0
log = logging.getLogger(__name__)


# --- bodies -----------------------------------------------------------------------------------


class CreateBody(BaseModel):
    env_id: str = Field(description="an hlvs environment id, e.g. hlvs/Kick-v0")
    kwargs: dict[str, Any] = Field(default_factory=dict, description="environment options")


class Created(BaseModel):
    instance_id: str


class Listing(BaseModel):
    all_envs: dict[str, str]


class ResetBody(BaseModel):
    seed: int | None = None


class ResetResult(BaseModel):
    observation: dict[str, Any]
    info: dict[str, Any]


class StepBody(BaseModel):
    action: list[float] = Field(description="motor position targets (rad), MOTOR_NAMES order")
    render: bool = False


class StepResult(BaseModel):
    observation: dict[str, Any]
    reward: float
    done: bool
    terminated: bool
    truncated: bool
    info: dict[str, Any]


class SpaceInfo(BaseModel):
    info: dict[str, Any]


class MonitorStartBody(BaseModel):
    directory: str | None = Field(default=None, description="ignored: the service chooses")
    force: bool = False
    resume: bool = False
    video: bool = False


class MonitorClosed(BaseModel):
    stats: dict[str, Any]


class MonitorFile(BaseModel):
    name: str
    bytes: int


class MonitorFiles(BaseModel):
    files: list[MonitorFile]


class Closed(BaseModel):
    closed: bool = True


# --- state ------------------------------------------------------------------------------------


@dataclass(eq=False)
class Instance:
    instance_id: str
    team_id: int
    token_id: str
    env_id: str
    env: Any
    folder: Path
    lock: threading.Lock = field(default_factory=threading.Lock)
    monitor: Monitor | None = None
    open: bool = True
    last_used_s: float = field(default_factory=time.monotonic)


class Registry:
    def __init__(self, *, per_token: int, idle_s: float) -> None:
        self.per_token = per_token
        self.idle_s = idle_s
        self.instances: dict[str, Instance] = {}
        self.lock = threading.Lock()

    def get(self, instance_id: str, team_id: int, *, live: bool = True) -> Instance:
        with self.lock:
            instance = self.instances.get(instance_id)
        if instance is None or instance.team_id != team_id or (live and not instance.open):
            raise NotFound(what="environment instance", ident=instance_id)
        instance.last_used_s = time.monotonic()
        return instance

    def close_idle(self) -> None:
        """Close instances nobody called for ``idle_s`` (with the registry lock held)."""
        now = time.monotonic()
        for instance in self.instances.values():
            if instance.open and now - instance.last_used_s > self.idle_s:
                with instance.lock:
                    _close(instance)
                log.info("closed idle environment %s of team %d", instance.instance_id,
                         instance.team_id)  # fmt: skip

    def open_count(self, token_id: str) -> int:
        return sum(1 for i in self.instances.values() if i.token_id == token_id and i.open)


def _registry(request: Request) -> Registry:
    registry: Registry = request.app.state.envs_registry
    return registry


def _data_dir(request: Request) -> Path:
    return Path(request.app.state.services.settings.data_dir) / "envs"


def _jsonable(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


# --- routes -----------------------------------------------------------------------------------


@router.post("/", status_code=201)
def create(body: CreateBody, principal: TeamPrincipal, request: Request) -> Created:
    import gymnasium as gym

    import envs  # registers the ids

    if body.env_id not in envs.ENV_IDS:
        raise InvalidInput(
            f"env_id {body.env_id!r} is not served; expected one of {list(envs.ENV_IDS)}",
            problems=[{"where": "body", "pointer": "/env_id", "message": "unknown environment"}],
        )
    unknown = sorted(set(body.kwargs) - ALLOWED_KWARGS)
    if unknown:
        raise InvalidInput(
            f"kwargs/{unknown[0]}: not an option here; allowed: {sorted(ALLOWED_KWARGS)}",
            problems=[
                {"where": "body", "pointer": f"/kwargs/{unknown[0]}", "message": "unknown option"}
            ],  # fmt: skip
        )
    registry = _registry(request)
    team_id = int(principal.team_id or 0)
    with registry.lock:
        registry.close_idle()
        token_id = str(principal.token_id)
        if registry.open_count(token_id) >= registry.per_token:
            raise Conflict(
                f"this token of team {principal.team_name} has {registry.per_token} environments"
                " open (the limit per token); close one first"
            )
        instance_id = secrets.token_hex(4)
        while instance_id in registry.instances:
            instance_id = secrets.token_hex(4)
        try:
            env = gym.make(body.env_id, **body.kwargs)
        except EnvConfigError as exc:
            raise InvalidInput(f"kwargs/{exc.field}: {exc}", problems=[
                {"where": "body", "pointer": f"/kwargs/{exc.field}", "message": str(exc),
                 "expected": exc.expected}]) from exc
        except (EnvError, TypeError, ValueError, OverflowError, RecursionError) as exc:
            raise InvalidInput(f"kwargs: {exc}") from exc
        folder = _data_dir(request) / str(team_id) / instance_id
        registry.instances[instance_id] = Instance(
            instance_id=instance_id,
            team_id=team_id,
            token_id=token_id,
            env_id=body.env_id,
            env=env,
            folder=folder,
        )
    return Created(instance_id=instance_id)


@router.get("/")
def listing(principal: TeamPrincipal, request: Request) -> Listing:
    registry = _registry(request)
    with registry.lock:
        mine = {
            i.instance_id: i.env_id
            for i in registry.instances.values()
            if i.team_id == principal.team_id and i.open
        }
    return Listing(all_envs=mine)


@router.post("/{instance_id}/reset/")
def reset(
    instance_id: str, body: ResetBody, principal: TeamPrincipal, request: Request
) -> ResetResult:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    with instance.lock:
        obs, info = instance.env.reset(seed=body.seed)
        if instance.monitor is not None:
            instance.monitor.on_reset(int(info.get("sim_time_ms", 0)))
    return ResetResult(observation=_jsonable(obs), info=_jsonable(info))


@router.post("/{instance_id}/step/")
def step(
    instance_id: str, body: StepBody, principal: TeamPrincipal, request: Request
) -> StepResult:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    action = np.asarray(body.action, dtype=np.float32)
    with instance.lock:
        try:
            obs, reward, terminated, truncated, info = instance.env.step(action)
        except EnvError as exc:
            raise InvalidInput(f"step: {exc}") from exc
        if instance.monitor is not None:
            instance.monitor.on_step(float(reward), terminated, truncated, info)
    return StepResult(
        observation=_jsonable(obs), reward=float(reward), done=bool(terminated or truncated),
        terminated=bool(terminated), truncated=bool(truncated), info=_jsonable(info),
    )  # fmt: skip


@router.get("/{instance_id}/action_space/")
def action_space(instance_id: str, principal: TeamPrincipal, request: Request) -> SpaceInfo:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    space = instance.env.action_space
    return SpaceInfo(info={"name": type(space).__name__, "shape": list(space.shape),
                           "low": space.low.tolist(), "high": space.high.tolist()})  # fmt: skip


@router.post("/{instance_id}/monitor/start/")
def monitor_start(
    instance_id: str, body: MonitorStartBody, principal: TeamPrincipal, request: Request
) -> Closed:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    with instance.lock:
        if instance.monitor is not None:
            raise Conflict("the monitor of this instance is already running")
        if instance.folder.exists() and body.force:
            shutil.rmtree(instance.folder)
        elif instance.folder.exists() and any(instance.folder.iterdir()) and not body.resume:
            raise Conflict("monitor files exist: pass force (clear them) or resume (append)")
        unwrapped = instance.env.unwrapped

        def world() -> Any:
            return getattr(unwrapped.session, "world", None)

        instance.monitor = Monitor(instance.folder, video=body.video, world_of=world)
    return Closed(closed=False)


@router.post("/{instance_id}/monitor/close/")
def monitor_close(instance_id: str, principal: TeamPrincipal, request: Request) -> MonitorClosed:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    with instance.lock:
        if instance.monitor is None:
            raise Conflict("no monitor is running on this instance")
        stats = instance.monitor.close()
        instance.monitor = None
    return MonitorClosed(stats=dict(stats))


@router.get("/{instance_id}/monitor/files/")
def monitor_files(instance_id: str, principal: TeamPrincipal, request: Request) -> MonitorFiles:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0), live=False)
    files = (
        sorted(p for p in instance.folder.glob("*") if p.is_file())
        if instance.folder.exists()
        else []
    )
    return MonitorFiles(files=[MonitorFile(name=p.name, bytes=p.stat().st_size) for p in files])


@router.get("/{instance_id}/monitor/files/{name}")
def monitor_file(
    instance_id: str, name: str, principal: TeamPrincipal, request: Request
) -> FileResponse:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0), live=False)
    path = instance.folder / name
    if "/" in name or name.startswith(".") or not path.is_file():
        raise NotFound(what="monitor file", ident=name)
    return FileResponse(path, filename=name)


@router.post("/{instance_id}/close/")
def close(instance_id: str, principal: TeamPrincipal, request: Request) -> Closed:
    instance = _registry(request).get(instance_id, int(principal.team_id or 0))
    with instance.lock:
        _close(instance)
    return Closed()


def _close(instance: Instance) -> None:
    if instance.monitor is not None:
        instance.monitor.close()
        instance.monitor = None
    if instance.open:
        instance.env.close()
        instance.open = False


def mount(app: FastAPI) -> None:
    per_token = int(os.environ.get("HLVS_ENVS_PER_TOKEN", str(DEFAULT_PER_TOKEN)))
    idle_s = float(os.environ.get("HLVS_ENVS_IDLE_S", str(DEFAULT_IDLE_S)))
    app.state.envs_registry = Registry(per_token=per_token, idle_s=idle_s)
    app.include_router(router)
