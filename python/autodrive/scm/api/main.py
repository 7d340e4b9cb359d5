"""The SCM's FastAPI application: the session middleware, the web app (static/) and the
routers of api/routes/.

Reading needs a login (viewer or operator); changing needs the operator role and the session's
CSRF token in the X-CSRF-Token header. Errors are JSON {"detail": "..."} naming what is wrong:
401 without a session, 403 naming the missing role or the bad CSRF token, 409 for a refused
light command, 422 for a malformed request, 429 for a login refused by its limits (an account
locked after failed logins, or an address that failed too often). Sessions end when idle or
old; pages carry a Content-Security-Policy; every refused request is in the event log
(api/middleware.py)."""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from fastapi import FastAPI
from fastapi.responses import FileResponse
from fastapi.staticfiles import StaticFiles
from starlette.middleware.sessions import SessionMiddleware

from autodrive.scm.api.routes import crl, events, lights, live, session, state, vehicles
from autodrive.scm.api.middleware import RefusalLog, SecurityHeaders, SessionExpiry
from autodrive.scm.core.security import SESSION_MAX_S, LoginLimiter, session_secret
from autodrive.scm.service import Scm

STATIC = Path(str(resources.files("autodrive.scm") / "static"))  # package data


def create_app(scm: Scm, tls: bool = False) -> FastAPI:
    """tls: served over HTTPS (--tls-cert): the session cookie is then Secure and HSTS is set."""
    app = FastAPI(
        title="AutoDRIVE Smart City Manager",
        description="Vehicles, traffic lights, signs and the event log of one map; light control "
        "(fixed-time, actuated, manual) with yellow, all-red and conflict interlocks.",
        version="1",
    )
    # Outermost last: the session, its expiry, the refusal log, the security headers.
    app.add_middleware(SecurityHeaders, hsts=tls)
    app.add_middleware(RefusalLog, scm=scm)
    app.add_middleware(SessionExpiry)
    app.add_middleware(
        SessionMiddleware,
        secret_key=session_secret(scm.sessions),
        session_cookie="scm_session",
        same_site="strict",
        max_age=int(SESSION_MAX_S),
        https_only=tls,
    )
    app.state.login_limiter = LoginLimiter()
    app.state.scm = scm
    app.state.map_payload = state.map_payload(scm)  # the map does not change while serving

    @app.get("/", include_in_schema=False)
    def index() -> FileResponse:
        return FileResponse(STATIC / "index.html")

    app.mount("/static", StaticFiles(directory=STATIC), name="static")
    for r in (session, state, vehicles, lights, events, live, crl):
        app.include_router(r.router)
    return app
