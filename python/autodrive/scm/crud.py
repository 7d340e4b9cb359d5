"""The SCM's reads of its database for the API: a car's pose history, pose counts and the
event log (the writes go through the service's writer thread, store.Writer)."""

from __future__ import annotations

from typing import Any

from sqlalchemy import func, select
from sqlalchemy.orm import Session

from autodrive.scm.models import Event, Pose, User

MAX_HISTORY_ROWS = 100000
MAX_EVENT_ROWS = 5000


def user_exists(s: Session, name: str) -> bool:
    """Whether the user name is taken (autodrive-scm user add refuses it without --reset)."""
    return s.get(User, name) is not None


def pose_history(s: Session, vehicle: str, limit: int) -> list[dict[str, Any]]:
    """The newest poses of a car's history (thinned), newest first; 1 <= limit <= 100000."""
    rows = s.scalars(
        select(Pose)
        .where(Pose.vehicle == vehicle)
        .order_by(Pose.id.desc())
        .limit(max(1, min(limit, MAX_HISTORY_ROWS)))
    ).all()
    return [
        {
            "utime": r.utime,
            "x_m": r.x_m,
            "y_m": r.y_m,
            "yaw_rad": r.yaw_rad,
            "speed_m_s": r.speed_m_s,
            "source": r.source,
            "seq": r.seq,
        }
        for r in rows
    ]


def pose_count(s: Session, vehicle: str | None) -> int:
    """Rows in the pose history (of one vehicle, or all)."""
    q = select(func.count()).select_from(Pose)
    if vehicle:
        q = q.where(Pose.vehicle == vehicle)
    return int(s.scalar(q) or 0)


def events(s: Session, since_id: int, limit: int) -> list[dict[str, Any]]:
    """The event log, oldest first after since_id; 1 <= limit <= 5000."""
    rows = s.scalars(
        select(Event)
        .where(Event.id > since_id)
        .order_by(Event.id)
        .limit(max(1, min(limit, MAX_EVENT_ROWS)))
    ).all()
    return [
        {
            "id": r.id,
            "utime": r.utime,
            "actor": r.actor,
            "kind": r.kind,
            "subject": r.subject,
            "detail": r.detail,
        }
        for r in rows
    ]
