"""``/v1/operator/nodes``: the match pool's machines for operators. Each node with its state
(and why it is drained or down), features, CPUs, load and memory, and the jobs on it; a job
that plays a submission's match names the submission and its teams. Operator tokens only."""

from __future__ import annotations

from fastapi import APIRouter, FastAPI
from pydantic import BaseModel, Field
from sqlalchemy import select

from service.db import Submission, Team
from service.deps import AppServices, DbSession, OperatorPrincipal, SessionRoute
from service.errors import NotFound

router = APIRouter(prefix="/v1/operator", tags=["operator"], route_class=SessionRoute)


class NodeJobView(BaseModel):
    job_id: str = Field(description="the Slurm job id, or the match process id (local pool)")
    state: str
    match_id: str | None = Field(description="the match the job plays, None for other jobs")
    submission_id: str | None = Field(description="the test match's submission, if it is one")
    team: str | None
    opponent: str | None


class NodeView(BaseModel):
    name: str
    state: str = Field(description="Slurm's node state (idle, allocated, drained, down...) "
                       "or 'up' for the local host")
    reason: str = Field(description="why the node is drained or down; empty otherwise")
    features: list[str]
    cpus: int
    cpus_allocated: int | None
    cpu_load: float | None = Field(description="1-minute load average")
    memory_mb: int
    memory_free_mb: int | None
    slots: int = Field(description="matches the node plays at once")
    jobs: list[NodeJobView]


class PoolView(BaseModel):
    pool: str = Field(description="local | slurm")
    slots: int = Field(description="test matches the service runs at once")
    nodes: list[NodeView]


@router.get("/nodes", responses={404: {"description": "the service has no match pool"},
                                 503: {"description": "the pool did not answer (e.g. the "
                                       "Slurm controller is down)"}})
def get_nodes(services: AppServices, principal: OperatorPrincipal,
              session: DbSession) -> PoolView:
    if services.pool is None:
        raise NotFound(what="match pool", ident="(the service runs without a worker)")
    nodes = services.pool.nodes()
    match_ids = {j.match_id for n in nodes for j in n.jobs if j.match_id}
    rows = {} if not match_ids else {
        row.match_id: (row.id, team, row.opponent)
        for row, team in session.execute(
            select(Submission, Team.name).join(Team, Team.id == Submission.team_id)
            .where(Submission.match_id.in_(match_ids)))
    }
    views = []
    for node in nodes:
        jobs = []
        for job in node.jobs:
            submission_id, team, opponent = rows.get(job.match_id, (None, None, None))
            jobs.append(NodeJobView(job_id=job.job_id, state=job.state, match_id=job.match_id,
                                    submission_id=submission_id, team=team, opponent=opponent))
        views.append(NodeView.model_validate({**node.to_json(), "jobs": jobs}))
    return PoolView(pool=services.settings.pool, slots=services.slots(), nodes=views)


def mount(app: FastAPI) -> None:
    app.include_router(router)


__all__ = ["mount", "router"]
