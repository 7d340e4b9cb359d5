"""The SCM's FastAPI application: the session middleware, the web app (static/) and the
routers of api/routes/.

Reading needs a login (viewer or operator); changing needs the operator role and the session's
CSRF token in the X-CSRF-Token header. Errors are JSON {"detail": "..."} naming what is wrong:
401 without a session, 403 naming the missing role or the bad CSRF token, 409 for a refused
light command, 422 for a malformed request."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles
from starlette.middleware.sessions import SessionMiddleware

from autodrive.scm.api.routes import events, lights, live, session, state, vehicles
from autodrive.scm.core.security import session_secret
from autodrive.scm.service import Scm

STATIC = Path(str(resources.files("autodrive.scm") / "static"))  # package data


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
    app.state.scm = scm
    app.state.map_payload = state.map_payload(scm)  # the map does not change while serving

    @app.get("/", include_in_schema=False)
    def index() -> FileResponse:
        return FileResponse(STATIC / "index.html")

    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    for r in (session, state, vehicles, lights, events, live):
        app.include_router(r.router)
    return app
