"""The first schema: vehicles, pose history, lights, signs, events, users, settings.

Revision ID: 0001
Revises:
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic import op

revision = "0001"
down_revision = None
branch_labels = None
depends_on = None

_ID = sa.BigInteger().with_variant(sa.Integer(), "sqlite")  # SQLite: ROWID autoincrement


def upgrade() -> None:
    op.create_table(
        "vehicles",
        sa.Column("name", sa.String(32), primary_key=True),
        sa.Column("x_m", sa.Float, nullable=False),
        sa.Column("y_m", sa.Float, nullable=False),
        sa.Column("yaw_rad", sa.Float, nullable=False),
        sa.Column("speed_m_s", sa.Float, nullable=False),
        sa.Column("source", sa.String(8), nullable=False),
        sa.Column("route", sa.String(64), nullable=False),
        sa.Column("lane", sa.String(64), nullable=False),
        sa.Column("status", sa.String(16), nullable=False),
        sa.Column("updated_us", sa.BigInteger, nullable=False),
    )
    op.create_table(
        "poses",
        sa.Column("id", _ID, primary_key=True, autoincrement=True),
        sa.Column("vehicle", sa.String(32), sa.ForeignKey("vehicles.name"), nullable=False),
        sa.Column("utime", sa.BigInteger, nullable=False),
        sa.Column("seq", sa.BigInteger, nullable=False),
        sa.Column("x_m", sa.Float, nullable=False),
        sa.Column("y_m", sa.Float, nullable=False),
        sa.Column("yaw_rad", sa.Float, nullable=False),
        sa.Column("speed_m_s", sa.Float, nullable=False),
        sa.Column("source", sa.String(8), nullable=False),
    )
    op.create_index("ix_poses_vehicle_utime", "poses", ["vehicle", "utime"])
    op.create_table(
        "lights",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=False),
        sa.Column("junction", sa.String(64), nullable=False),
        sa.Column("stop_line", sa.String(64), nullable=False),
        sa.Column("lane", sa.String(64), nullable=False),
        sa.Column("state", sa.String(8), nullable=False),
        sa.Column("sim_state", sa.String(8), nullable=False),
        sa.Column("mode", sa.String(16), nullable=False),
        sa.Column("program", sa.Text, nullable=False),
        sa.Column("updated_us", sa.BigInteger, nullable=False),
    )
    op.create_table(
        "signs",
        sa.Column("id", sa.Integer, primary_key=True, autoincrement=False),
        sa.Column("kind", sa.String(32), nullable=False),
        sa.Column("x_m", sa.Float, nullable=False),
        sa.Column("y_m", sa.Float, nullable=False),
        sa.Column("yaw_rad", sa.Float, nullable=False),
        sa.Column("lane", sa.String(64), nullable=False),
        sa.Column("speed_limit_m_s", sa.Float, nullable=False),
    )
    op.create_table(
        "events",
        sa.Column("id", _ID, primary_key=True, autoincrement=True),
        sa.Column("utime", sa.BigInteger, nullable=False),
        sa.Column("actor", sa.String(64), nullable=False),
        sa.Column("kind", sa.String(32), nullable=False),
        sa.Column("subject", sa.String(64), nullable=False),
        sa.Column("detail", sa.Text, nullable=False),
    )
    op.create_table(
        "users",
        sa.Column("name", sa.String(64), primary_key=True),
        sa.Column("role", sa.String(16), nullable=False),
        sa.Column("password_hash", sa.String(256), nullable=False),
        sa.Column("created_us", sa.BigInteger, nullable=False),
    )
    op.create_table(
        "settings",
        sa.Column("key", sa.String(64), primary_key=True),
        sa.Column("value", sa.Text, nullable=False),
    )


def downgrade() -> None:
    for table in ("settings", "users", "events", "signs", "lights", "poses", "vehicles"):
        op.drop_table(table)
