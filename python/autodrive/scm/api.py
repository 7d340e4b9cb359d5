"""The SCM's REST and WebSocket API (FastAPI; OpenAPI at /docs) and its web app (static/).

Reading needs a login (viewer or operator); changing needs the operator role and the session's
CSRF token in the X-CSRF-Token header. Errors are JSON {"detail": "..."} naming what is wrong:
401 without a session, 403 naming the missing role or the bad CSRF token, 409 for a refused
light command, 422 for a malformed request."""

from __future__ import annotations

import asyncio
import math
import secrets
import threading
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

from fastapi import Depends, FastAPI, HTTPException, Request, WebSocket, WebSocketDisconnect
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles
from pydantic import BaseModel, Field
from sqlalchemy import func, select
from starlette.middleware.sessions import SessionMiddleware

from autodrive.core import vehicle
from autodrive.scm.auth import check_login, session_secret
from autodrive.scm.lights import ControlError, ConflictError
from autodrive.scm.models import Event, Pose
from autodrive.scm.service import Scm

STATIC = Path(str(resources.files("autodrive.scm") / "static"))  # package data


class LoginIn(BaseModel):
    name: str = Field(min_length=1, max_length=64)
    password: str = Field(min_length=1, max_length=256)


class LightStateIn(BaseModel):
    state: Literal["OFF", "RED", "YELLOW", "GREEN"]


class ModeIn(BaseModel):
    mode: Literal["fixed", "actuated", "manual"]
    max_green_s: float | None = Field(default=None, ge=1.0, le=600.0)


class PhaseIn(BaseModel):
    state: Literal["RED", "YELLOW", "GREEN"]
    duration_s: float


class ProgramIn(BaseModel):
    offset_s: float = 0.0
    phases: list[PhaseIn] = Field(min_length=1)


class PoseIn(BaseModel):
    vehicle: str = Field(pattern=r"^[A-Z][A-Z0-9]*$", max_length=32)
    utime: int
    x_m: float
    y_m: float
    yaw_rad: float
    speed_m_s: float = 0.0
    seq: int = -1


class PosesIn(BaseModel):
    poses: list[PoseIn] = Field(min_length=1, max_length=10000)


def user_of(request: Request) -> dict[str, str]:
    """The logged-in user (any role); 401 without a session."""
    user = request.session.get("user")
    if not user:
        raise HTTPException(401, "login required: no session (POST /api/login first)")
    return {"name": str(user), "role": str(request.session.get("role", ""))}


def operator_of(request: Request) -> dict[str, str]:
    """An operator with the session's CSRF token in X-CSRF-Token; 401 / 403 saying what lacks."""
    user = user_of(request)
    if user["role"] != "operator":
        raise HTTPException(
            403, f"operator role required: user '{user['name']}' has role '{user['role']}'"
        )
    token = request.headers.get("x-csrf-token", "")
    if not token or not secrets.compare_digest(token, str(request.session.get("csrf", ""))):
        raise HTTPException(
            403, "CSRF token missing or wrong: send header X-CSRF-Token from GET /api/session"
        )
    return user


Viewer = Annotated[dict[str, str], Depends(user_of)]
Operator = Annotated[dict[str, str], Depends(operator_of)]


def map_payload(scm: Scm) -> dict[str, Any]:
    m = scm.map
    lanes = []
    for name, g in scm.roadnet.lanes.items():
        step = max(1, len(g.pts) // 40)
        pts = g.pts[::step, :2].round(3).tolist()
        if len(g.pts) % step != 1:
            pts.append(g.pts[-1, :2].round(3).tolist())
        lanes.append({"name": name, "half_width_m": g.half_width_m, "points": pts})
    stops = []
    for s in m.all_stop_lines():
        yaw = m.stop_line_yaw_rad(s)
        h = s.length_m / 2
        c = s.centre_m
        stops.append(
            {
                "name": s.name,
                "from": [c[0] - h * math.cos(yaw), c[1] - h * math.sin(yaw)],
                "to": [c[0] + h * math.cos(yaw), c[1] + h * math.sin(yaw)],
            }
        )
    v = vehicle.load()
    return {
        "name": m.name,
        "half_size_m": m.floor_half_size_m,
        "lanes": lanes,
        "stop_lines": stops,
        "lights": [
            {
                "id": t.id,
                "x_m": t.position_m[0],
                "y_m": t.position_m[1],
                "yaw_rad": t.yaw_rad,
                "stop_line": t.stop_line,
            }
            for t in m.lights()
        ],
        "signs": [
            {
                "id": s.id,
                "kind": s.kind,
                "x_m": s.position_m[0],
                "y_m": s.position_m[1],
                "yaw_rad": s.yaw_rad,
                "speed_limit_m_s": s.speed_limit_m_s,
            }
            for s in m.placed_signs()
        ],
        "conflicts": m.light_conflicts(),
        "footprint": {
            "length_m": v.envelope_length_m,
            "width_m": v.envelope_width_m,
            "centre_ahead_m": v.envelope_center_ahead_m,
        },
    }


def create_app(scm: Scm) -> FastAPI:
    app = FastAPI(
        title="AutoDRIVE Smart City Manager",
        description="Vehicles, traffic lights, signs and the event log of one map; light control "
        "(fixed-time, actuated, manual) with yellow, all-red and conflict interlocks.",
        version="1",
    )
    app.add_middleware(
        SessionMiddleware,
        secret_key=session_secret(scm.sessions),
        session_cookie="scm_session",
        same_site="strict",
        max_age=12 * 3600,
    )
    cached_map = map_payload(scm)

    @app.get("/", include_in_schema=False)
    def index() -> FileResponse:
        return FileResponse(STATIC / "index.html")

    app.mount("/static", StaticFiles(directory=STATIC), name="static")

    @app.post("/api/login", tags=["session"])
    def login(body: LoginIn, request: Request) -> dict[str, str]:
        user = check_login(scm.sessions, body.name, body.password)
        if user is None:
            raise HTTPException(401, "wrong user name or password")
        request.session.clear()
        request.session.update(user=user.name, role=user.role, csrf=secrets.token_urlsafe(24))
        scm.event(user.name, "login", user.name, {"role": user.role})
        return {"user": user.name, "role": user.role, "csrf": request.session["csrf"]}

    @app.post("/api/logout", tags=["session"])
    def logout(request: Request) -> dict[str, bool]:
        request.session.clear()
        return {"ok": True}

    @app.get("/api/session", tags=["session"])
    def session(user: Viewer, request: Request) -> dict[str, str]:
        return {**{"user": user["name"], "role": user["role"]}, "csrf": request.session["csrf"]}

    @app.get("/api/status", tags=["state"])
    def status() -> dict[str, Any]:
        """Health, no login needed: ready (the LCM threads, the pose receiver process and
        the database writer all run: what tools/demo waits for), counters of the LCM and
        database sides."""
        snap = scm.snapshot()
        return {"ok": True, "ready": scm.ready(), "map": scm.map.name, "stats": snap["stats"]}

    @app.get("/api/map", tags=["state"])
    def get_map(_: Viewer) -> dict[str, Any]:
        """Lanes, stop lines, lights, signs, conflicts and the car's footprint, for drawing."""
        return cached_map

    @app.get("/api/state", tags=["state"])
    def get_state(_: Viewer) -> dict[str, Any]:
        """Everything live: vehicles, lights, junctions, the last events, counters."""
        return scm.snapshot()

    @app.get("/api/vehicles", tags=["vehicles"])
    def vehicles(_: Viewer) -> list[dict[str, Any]]:
        return list(scm.snapshot()["vehicles"])

    @app.get("/api/vehicles/{name}/history", tags=["vehicles"])
    def history(name: str, _: Viewer, limit: int = 500) -> list[dict[str, Any]]:
        """The newest poses of a car's history (thinned), newest first; limit <= 100000."""
        with scm.sessions() as s:
            rows = s.scalars(
                select(Pose)
                .where(Pose.vehicle == name)
                .order_by(Pose.id.desc())
                .limit(max(1, min(limit, 100000)))
            ).all()
            if not rows and name not in scm.cars:
                raise HTTPException(404, f"no vehicle '{name}'")
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

    @app.get("/api/poses/count", tags=["vehicles"])
    def pose_count(_: Viewer, vehicle: str | None = None) -> dict[str, int]:
        """Rows in the pose history (of one vehicle, or all)."""
        with scm.sessions() as s:
            q = select(func.count()).select_from(Pose)
            if vehicle:
                q = q.where(Pose.vehicle == vehicle)
            return {"rows": int(s.scalar(q) or 0)}

    @app.post("/api/poses", tags=["vehicles"])
    def ingest(body: PosesIn, user: Operator) -> dict[str, int]:
        """Poses from a script, all kept in the history; the answer comes only after they are
        committed to the database (a 503 or no answer: not stored)."""
        for p in body.poses:
            scm.pose(p.vehicle, p.utime, p.x_m, p.y_m, p.yaw_rad, p.speed_m_s, "rest", p.seq, True)
        done = threading.Event()
        scm.writer.ack(done)
        if not done.wait(timeout=30):
            raise HTTPException(503, "the database did not commit within 30 s: not stored")
        return {"stored": len(body.poses)}

    @app.get("/api/lights", tags=["lights"])
    def lights(_: Viewer) -> list[dict[str, Any]]:
        return list(scm.snapshot()["lights"])

    @app.put("/api/lights/{light_id}/state", tags=["lights"])
    def set_light(light_id: int, body: LightStateIn, user: Operator) -> dict[str, str]:
        """Sets a light (its junction goes to manual). GREEN -> RED passes through YELLOW; a
        GREEN waits for the all-red time; a GREEN against a conflicting green is refused (409)."""
        try:
            return {"plan": scm.set_light(light_id, body.state, user["name"])}
        except ConflictError as err:
            raise HTTPException(409, str(err)) from err
        except ControlError as err:
            code = 404 if "no traffic light" in str(err) else 409
            raise HTTPException(code, str(err)) from err

    @app.put("/api/lights/{light_id}/program", tags=["lights"])
    def set_program(light_id: int, body: ProgramIn, user: Operator) -> dict[str, Any]:
        """A light's fixed-time program; refused (409) if conflicting lights would meet."""
        try:
            return scm.set_program(light_id, body.model_dump(), user["name"]).to_json()
        except ConflictError as err:
            raise HTTPException(409, str(err)) from err
        except ControlError as err:
            code = 404 if "no traffic light" in str(err) else 422
            raise HTTPException(code, str(err)) from err

    @app.put("/api/junctions/{name}/mode", tags=["lights"])
    def set_mode(name: str, body: ModeIn, user: Operator) -> dict[str, str]:
        try:
            scm.set_mode(name, body.mode, user["name"], body.max_green_s)
        except ControlError as err:
            raise HTTPException(404, str(err)) from err
        return {"junction": name, "mode": body.mode}

    @app.get("/api/signs", tags=["state"])
    def signs(_: Viewer) -> list[dict[str, Any]]:
        return list(cached_map["signs"])

    @app.get("/api/events", tags=["events"])
    def events(_: Viewer, since_id: int = 0, limit: int = 200) -> list[dict[str, Any]]:
        """The event log from the database, oldest first after since_id."""
        with scm.sessions() as s:
            rows = s.scalars(
                select(Event)
                .where(Event.id > since_id)
                .order_by(Event.id)
                .limit(max(1, min(limit, 5000)))
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

    @app.websocket("/ws")
    async def live(ws: WebSocket) -> None:
        """The state of GET /api/state, pushed every 100 ms (needs a session cookie)."""
        if not ws.session.get("user"):
            await ws.close(code=4401, reason="login required")
            return
        await ws.accept()
        try:
            while True:
                await ws.send_json(scm.snapshot())
                await asyncio.sleep(0.1)
        except (WebSocketDisconnect, RuntimeError):
            return

    return app
