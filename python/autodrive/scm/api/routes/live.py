"""/ws: the state of GET /api/state pushed every 100 ms to a logged-in browser."""

from __future__ import annotations

import asyncio

from fastapi import APIRouter, WebSocket, WebSocketDisconnect

from autodrive.scm.service import Scm

router = APIRouter()
PUSH_PERIOD_S = 0.1


@router.websocket("/ws")
async def live(ws: WebSocket) -> None:
    """The state of GET /api/state, pushed every 100 ms (needs a session cookie)."""
    if not ws.session.get("user"):
        await ws.close(code=4401, reason="login required")
        return
    scm: Scm = ws.app.state.scm
    await ws.accept()
    try:
        while True:
            await ws.send_json(scm.snapshot())
            await asyncio.sleep(PUSH_PERIOD_S)
    except (WebSocketDisconnect, RuntimeError):
        return
