"""GET /api/crl: the testbed CA's revocation list (ca/ca.crl, signed by the CA, base64), for
every receiver of signed V2X messages to fetch; public like the CA's certificate."""

from __future__ import annotations

from fastapi import APIRouter, HTTPException
from fastapi.responses import PlainTextResponse

from autodrive.core.v2x_ca import Authority

router = APIRouter(prefix="/api", tags=["security"])


@router.get("/crl", response_class=PlainTextResponse)
def crl() -> str:
    """The revocation list, one line of base64 (format: docs/design/threat-model.md)."""
    path = Authority().crl_path
    try:
        return path.read_text()
    except OSError as err:
        raise HTTPException(503, f"{path}: no revocation list ({err.strerror})") from None
