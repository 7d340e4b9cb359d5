"""What the routes depend on: the running service (app.state.scm), the map drawing computed
once (app.state.map_payload), the logged-in user (any role; 401 without a session) and the
operator who echoes the session's CSRF token (403 naming what is missing)."""

from __future__ import annotations

import secrets
from typing import Annotated, Any

from fastapi import Depends, HTTPException, Request

from autodrive.scm.service import Scm


def scm_of(request: Request) -> Scm:
    scm: Scm = request.app.state.scm
    return scm


def map_payload_of(request: Request) -> dict[str, Any]:
    payload: dict[str, Any] = request.app.state.map_payload
    return payload


def user_of(request: Request) -> dict[str, str]:
    """The logged-in user (any role); 401 without a session."""
    user = request.session.get("user")
    if not user:
        ended = request.scope.get("session_ended")  # set by api/middleware.SessionExpiry
        raise HTTPException(401, f"login required: {ended or 'no session'} (POST /api/login)")
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


ScmDep = Annotated[Scm, Depends(scm_of)]
MapPayload = Annotated[dict[str, Any], Depends(map_payload_of)]
Viewer = Annotated[dict[str, str], Depends(user_of)]
Operator = Annotated[dict[str, str], Depends(operator_of)]
