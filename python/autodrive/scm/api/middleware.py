"""The SCM's request guards, as ASGI middleware (plain ASGI: they see the WebSocket too):

- SessionExpiry ends a session that is idle or old (core.security.session_expired), before any
  route sees it; the 401 then says why (scope["session_ended"]).
- SecurityHeaders puts a Content-Security-Policy (only this server's own scripts, styles and
  connections; no inline script, no framing) and its companions on every page and answer.
- RefusalLog writes every refused request (status 4xx) to the SCM's event log: who (user or
  address), method, path and status; a refused login answers LOGIN_REFUSED_DELAY_S late."""

from __future__ import annotations

import asyncio
import time
from typing import Any

from starlette.types import ASGIApp, Message, Receive, Scope, Send

from autodrive.scm.core.security import LOGIN_REFUSED_DELAY_S, session_expired

CONTENT_SECURITY_POLICY = (
    "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; "
    "connect-src 'self'; object-src 'none'; base-uri 'none'; form-action 'self'; "
    "frame-ancestors 'none'"
)
SECURITY_HEADERS = (
    (b"content-security-policy", CONTENT_SECURITY_POLICY.encode()),
    (b"x-content-type-options", b"nosniff"),
    (b"x-frame-options", b"DENY"),
    (b"referrer-policy", b"no-referrer"),
)
# FastAPI's interactive API pages load Swagger UI / ReDoc scripts from a CDN: they keep their
# own headers (the API they call is guarded all the same).
API_DOC_PATHS = ("/docs", "/redoc")


class SessionExpiry:
    def __init__(self, app: ASGIApp) -> None:
        self.app = app

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] in ("http", "websocket"):
            session: dict[str, Any] = scope.get("session", {})
            if session.get("user"):
                now = time.time()
                why = session_expired(session, now)
                if why:
                    session.clear()
                    scope["session_ended"] = why
                else:
                    session["seen_s"] = now
        await self.app(scope, receive, send)


class SecurityHeaders:
    def __init__(self, app: ASGIApp, hsts: bool = False) -> None:
        self.app = app
        self.headers = SECURITY_HEADERS + (
            ((b"strict-transport-security", b"max-age=31536000"),) if hsts else ()
        )

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http" or scope["path"].startswith(API_DOC_PATHS):
            await self.app(scope, receive, send)
            return

        async def with_headers(message: Message) -> None:
            if message["type"] == "http.response.start":
                message.setdefault("headers", [])
                message["headers"] = list(message["headers"]) + list(self.headers)
            await send(message)

        await self.app(scope, receive, with_headers)


class RefusalLog:
    """Outermost but for the session: sees the final status and the session's user."""

    def __init__(self, app: ASGIApp, scm: Any) -> None:
        self.app = app
        self.scm = scm

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            await self.app(scope, receive, send)
            return

        async def watch(message: Message) -> None:
            if message["type"] == "http.response.start" and 400 <= message["status"] < 500:
                client = scope.get("client")
                address = client[0] if client else "unknown"
                user = scope.get("session", {}).get("user")
                self.scm.event(
                    str(user) if user else address,
                    "request_refused",
                    f"{scope['method']} {scope['path']}",
                    {"status": message["status"], "address": address},
                )
                if scope["path"] == "/api/login":
                    await asyncio.sleep(LOGIN_REFUSED_DELAY_S)
            await send(message)

        await self.app(scope, receive, watch)
