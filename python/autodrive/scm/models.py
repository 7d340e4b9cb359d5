"""The SCM's database schema (SQLAlchemy 2 declarative models). Alembic's migrations
(migrations/versions/) create it; this module is what the code reads and writes through."""

from __future__ import annotations

from sqlalchemy import BigInteger, Float, ForeignKey, Index, Integer, String, Text
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column


class Base(DeclarativeBase):
    pass


class Vehicle(Base):
    """A car: its latest pose and speed and its status (ok / stale)."""

    __tablename__ = "vehicles"
    name: Mapped[str] = mapped_column(String(32), primary_key=True)
    x_m: Mapped[float] = mapped_column(Float, default=0.0)
    y_m: Mapped[float] = mapped_column(Float, default=0.0)
    yaw_rad: Mapped[float] = mapped_column(Float, default=0.0)
    speed_m_s: Mapped[float] = mapped_column(Float, default=0.0)
    source: Mapped[str] = mapped_column(String(8), default="")  # eye / ekf / rest
    route: Mapped[str] = mapped_column(String(64), default="")
    lane: Mapped[str] = mapped_column(String(64), default="")
    status: Mapped[str] = mapped_column(String(16), default="unseen")
    updated_us: Mapped[int] = mapped_column(BigInteger, default=0)  # wall clock [us]


class Pose(Base):
    """Pose history, thinned to --history-hz per car (0: every pose)."""

    __tablename__ = "poses"
    id: Mapped[int] = mapped_column(BigInteger().with_variant(Integer, "sqlite"), primary_key=True)
    vehicle: Mapped[str] = mapped_column(String(32), ForeignKey("vehicles.name"))
    utime: Mapped[int] = mapped_column(BigInteger)  # the pose's own stamp [us]
    seq: Mapped[int] = mapped_column(BigInteger, default=-1)  # the sender's counter, -1 if none
    x_m: Mapped[float] = mapped_column(Float)
    y_m: Mapped[float] = mapped_column(Float)
    yaw_rad: Mapped[float] = mapped_column(Float)
    speed_m_s: Mapped[float] = mapped_column(Float)
    source: Mapped[str] = mapped_column(String(8))
    __table_args__ = (Index("ix_poses_vehicle_utime", "vehicle", "utime"),)


class Light(Base):
    """A traffic light: its junction, current state, control mode and program (JSON: offset_s
    and a list of phases {state, duration_s})."""

    __tablename__ = "lights"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    junction: Mapped[str] = mapped_column(String(64))
    stop_line: Mapped[str] = mapped_column(String(64))
    lane: Mapped[str] = mapped_column(String(64))
    state: Mapped[str] = mapped_column(String(8), default="RED")
    sim_state: Mapped[str] = mapped_column(String(8), default="")
    mode: Mapped[str] = mapped_column(String(16), default="fixed")
    program: Mapped[str] = mapped_column(Text)
    updated_us: Mapped[int] = mapped_column(BigInteger, default=0)


class Sign(Base):
    """A sign as the map description places it (loaded at start, never typed in)."""

    __tablename__ = "signs"
    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    kind: Mapped[str] = mapped_column(String(32))
    x_m: Mapped[float] = mapped_column(Float)
    y_m: Mapped[float] = mapped_column(Float)
    yaw_rad: Mapped[float] = mapped_column(Float)
    lane: Mapped[str] = mapped_column(String(64), default="")
    speed_limit_m_s: Mapped[float] = mapped_column(Float, default=-1.0)


class Event(Base):
    """Every change and who made it (actor: a user name, 'program', 'actuated', 'server')."""

    __tablename__ = "events"
    id: Mapped[int] = mapped_column(BigInteger().with_variant(Integer, "sqlite"), primary_key=True)
    utime: Mapped[int] = mapped_column(BigInteger)  # wall clock [us]
    actor: Mapped[str] = mapped_column(String(64))
    kind: Mapped[str] = mapped_column(String(32))
    subject: Mapped[str] = mapped_column(String(64))
    detail: Mapped[str] = mapped_column(Text, default="")


class User(Base):
    __tablename__ = "users"
    name: Mapped[str] = mapped_column(String(64), primary_key=True)
    role: Mapped[str] = mapped_column(String(16))  # operator / viewer
    password_hash: Mapped[str] = mapped_column(String(256))
    created_us: Mapped[int] = mapped_column(BigInteger)


class Setting(Base):
    """Server settings kept with the data (the session-signing secret)."""

    __tablename__ = "settings"
    key: Mapped[str] = mapped_column(String(64), primary_key=True)
    value: Mapped[str] = mapped_column(Text)
