"""The event log (logins, light commands, mode changes, ...) from the database."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter

from autodrive.scm import crud
from autodrive.scm.api.deps import ScmDep, Viewer

router = APIRouter(prefix="/api", tags=["events"])


@router.get("/events")
def events(_: Viewer, scm: ScmDep, since_id: int = 0, limit: int = 200) -> list[dict[str, Any]]:
    """The event log from the database, oldest first after since_id."""
    with scm.sessions() as s:
        return crud.events(s, since_id, limit)
