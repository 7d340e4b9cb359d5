"""Traffic lights: their states, a light set by hand, a light's program, a junction's mode.
Refused commands are 409 (conflicting greens) or 404 (no such light or junction)."""

from __future__ import annotations

from typing import Any

from fastapi import APIRouter, HTTPException

from autodrive.scm.api.deps import Operator, ScmDep, Viewer
from autodrive.scm.lights import ConflictError, ControlError
from autodrive.scm.schemas import LightStateIn, ModeIn, ProgramIn

router = APIRouter(prefix="/api", tags=["lights"])


def _refused(err: ControlError, otherwise: int) -> HTTPException:
    """A conflict is 409; a missing light 404; any other refusal `otherwise`."""
    if isinstance(err, ConflictError):
        return HTTPException(409, str(err))
    return HTTPException(404 if "no traffic light" in str(err) else otherwise, str(err))


@router.get("/lights")
def lights(_: Viewer, scm: ScmDep) -> list[dict[str, Any]]:
    return list(scm.snapshot()["lights"])


@router.put("/lights/{light_id}/state")
def set_light(light_id: int, body: LightStateIn, user: Operator, scm: ScmDep) -> dict[str, str]:
    """Sets a light (its junction goes to manual). GREEN -> RED passes through YELLOW; a
    GREEN waits for the all-red time; a GREEN against a conflicting green is refused (409)."""
    try:
        return {"plan": scm.set_light(light_id, body.state, user["name"])}
    except ControlError as err:
        raise _refused(err, 409) from err


@router.put("/lights/{light_id}/program")
def set_program(light_id: int, body: ProgramIn, user: Operator, scm: ScmDep) -> dict[str, Any]:
    """A light's fixed-time program; refused (409) if conflicting lights would meet."""
    try:
        return scm.set_program(light_id, body.model_dump(), user["name"]).to_json()
    except ControlError as err:
        raise _refused(err, 422) from err


@router.put("/junctions/{name}/mode")
def set_mode(name: str, body: ModeIn, user: Operator, scm: ScmDep) -> dict[str, str]:
    try:
        scm.set_mode(name, body.mode, user["name"], body.max_green_s)
    except ControlError as err:
        raise HTTPException(404, str(err)) from err
    return {"junction": name, "mode": body.mode}
