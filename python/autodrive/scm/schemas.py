"""The bodies the SCM's API accepts (Pydantic; FastAPI answers 422 naming a malformed field)."""

from __future__ import annotations

from typing import Literal

from pydantic import BaseModel, Field


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
