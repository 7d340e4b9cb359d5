"""Login, logout and the session (user, role and the CSRF token changes must echo)."""

from __future__ import annotations

import secrets

from fastapi import APIRouter, HTTPException, Request

from autodrive.scm.api.deps import ScmDep, Viewer
from autodrive.scm.core.security import check_login
from autodrive.scm.schemas import LoginIn

router = APIRouter(prefix="/api", tags=["session"])


@router.post("/login")
def login(body: LoginIn, request: Request, scm: ScmDep) -> dict[str, str]:
    user = check_login(scm.sessions, body.name, body.password)
    if user is None:
        raise HTTPException(401, "wrong user name or password")
    request.session.clear()
    request.session.update(user=user.name, role=user.role, csrf=secrets.token_urlsafe(24))
    scm.event(user.name, "login", user.name, {"role": user.role})
    return {"user": user.name, "role": user.role, "csrf": request.session["csrf"]}


@router.post("/logout")
def logout(request: Request) -> dict[str, bool]:
    request.session.clear()
    return {"ok": True}


@router.get("/session")
def session(user: Viewer, request: Request) -> dict[str, str]:
    return {**{"user": user["name"], "role": user["role"]}, "csrf": request.session["csrf"]}
