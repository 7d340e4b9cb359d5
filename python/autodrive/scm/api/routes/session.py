"""Login, logout and the session (user, role and the CSRF token changes must echo)."""

from __future__ import annotations

import secrets
import time

from fastapi import APIRouter, HTTPException, Request
from starlette.concurrency import run_in_threadpool

from autodrive.scm.api.deps import Viewer
from autodrive.scm.core.security import LoginLimiter, LoginRefused, check_login
from autodrive.scm.schemas import LoginIn
from autodrive.scm.service import Scm

router = APIRouter(prefix="/api", tags=["session"])


@router.post("/login")
async def login(body: LoginIn, request: Request) -> dict[str, str]:
    # async, without a sync dependency: a refused try (a brute force's 999 of 1,000) is answered
    # on the event loop and costs no worker thread; only the password hash (argon2, ~0.1 s of
    # CPU) goes to one.
    scm: Scm = request.app.state.scm
    limiter: LoginLimiter = request.app.state.login_limiter
    address = request.client.host if request.client else "unknown"
    try:
        limiter.check(body.name, address)  # before any password hash is computed
    except LoginRefused as refused:
        raise HTTPException(429, str(refused)) from None
    user = await run_in_threadpool(check_login, scm.sessions, body.name, body.password)
    if user is None:
        limiter.failed(body.name, address)
        if limiter.locked(body.name):
            scm.event(address, "account_locked", body.name, {"address": address})
        raise HTTPException(401, "wrong user name or password")
    limiter.succeeded(user.name)
    now = time.time()
    request.session.clear()
    request.session.update(user=user.name, role=user.role, csrf=secrets.token_urlsafe(24),
                           login_s=now, seen_s=now)  # fmt: skip
    scm.event(user.name, "login", user.name, {"role": user.role})
    return {"user": user.name, "role": user.role, "csrf": request.session["csrf"]}


@router.post("/logout")
def logout(request: Request) -> dict[str, bool]:
    request.session.clear()
    return {"ok": True}


@router.get("/session")
def session(user: Viewer, request: Request) -> dict[str, str]:
    return {**{"user": user["name"], "role": user["role"]}, "csrf": request.session["csrf"]}
