"""The cars: their live state, their pose history, and poses sent by a script."""

from __future__ import annotations

import threading
from typing import Any

from fastapi import APIRouter, HTTPException

from autodrive.scm import crud
from autodrive.scm.api.deps import Operator, ScmDep, Viewer
from autodrive.scm.schemas import PosesIn

router = APIRouter(prefix="/api", tags=["vehicles"])
COMMIT_TIMEOUT_S = 30.0  # POST /api/poses answers 503 when the writer has not committed by then


@router.get("/vehicles")
def vehicles(_: Viewer, scm: ScmDep) -> list[dict[str, Any]]:
    return list(scm.snapshot()["vehicles"])


@router.get("/vehicles/{name}/history")
def history(name: str, _: Viewer, scm: ScmDep, limit: int = 500) -> list[dict[str, Any]]:
    """The newest poses of a car's history (thinned), newest first; limit <= 100000."""
    with scm.sessions() as s:
        rows = crud.pose_history(s, name, limit)
    if not rows and name not in scm.cars:
        raise HTTPException(404, f"no vehicle '{name}'")
    return rows


@router.get("/poses/count")
def pose_count(_: Viewer, scm: ScmDep, vehicle: str | None = None) -> dict[str, int]:
    """Rows in the pose history (of one vehicle, or all)."""
    with scm.sessions() as s:
        return {"rows": crud.pose_count(s, vehicle)}


@router.post("/poses")
def ingest(body: PosesIn, user: Operator, scm: ScmDep) -> dict[str, int]:
    """Poses from a script, all kept in the history; the answer comes only after they are
    committed to the database (a 503 or no answer: not stored)."""
    for p in body.poses:
        scm.pose(p.vehicle, p.utime, p.x_m, p.y_m, p.yaw_rad, p.speed_m_s, "rest", p.seq, True)
    done = threading.Event()
    scm.writer.ack(done)
    if not done.wait(timeout=COMMIT_TIMEOUT_S):
        raise HTTPException(503, "the database did not commit within 30 s: not stored")
    return {"stored": len(body.poses)}
