"""Alembic environment of the SCM: run in process by autodrive.scm.core.db.migrate with an
open connection (config.attributes["connection"]); there is no alembic.ini."""

from __future__ import annotations

from alembic import context

from autodrive.scm.models import Base

connection = context.config.attributes["connection"]
context.configure(connection=connection, target_metadata=Base.metadata)
with context.begin_transaction():
    context.run_migrations()
