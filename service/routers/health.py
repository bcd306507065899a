"""``GET /v1/health``: the service answers and its database too (no token needed)."""

from __future__ import annotations

from fastapi import APIRouter, FastAPI
from pydantic import BaseModel
from sqlalchemy import text

from service.deps import DbSession, SessionRoute

router = APIRouter(prefix="/v1", tags=["health"], route_class=SessionRoute)


class Health(BaseModel):
    status: str
    database: str


@router.get("/health")
def health(session: DbSession) -> Health:
    session.execute(text("SELECT 1"))
    return Health(status="ok", database=session.get_bind().dialect.name)


def mount(app: FastAPI) -> None:
    app.include_router(router)
