"""The SCM's database: an engine for SQLite (WAL mode, under out/scm/ by default) or PostgreSQL
(--db postgresql://...), brought to the newest schema with Alembic on start."""

from __future__ import annotations

from importlib import resources
from pathlib import Path
from typing import Any

from alembic import command
from alembic.config import Config
from sqlalchemy import Engine, create_engine, event
from sqlalchemy.engine import make_url
from sqlalchemy.exc import ArgumentError, OperationalError, SQLAlchemyError
from sqlalchemy.orm import Session, sessionmaker

MIGRATIONS = Path(str(resources.files("autodrive.scm") / "migrations"))  # package data


class DatabaseError(RuntimeError):
    """A database URL that cannot be used; the message names the URL and the problem."""


def _sqlite_pragmas(dbapi_conn: Any, _record: Any) -> None:
    cur = dbapi_conn.cursor()
    cur.execute("PRAGMA journal_mode=WAL")  # readers never block the pose writer
    cur.execute("PRAGMA synchronous=FULL")  # a commit is on disk before it is acknowledged
    cur.execute("PRAGMA foreign_keys=ON")
    cur.execute("PRAGMA busy_timeout=5000")
    cur.close()


def normalise(url: str) -> str:
    """postgresql:// (no driver named) means psycopg 3 here."""
    if url.startswith("postgresql://") or url.startswith("postgres://"):
        return "postgresql+psycopg://" + url.split("://", 1)[1]
    return url


def open_engine(url: str) -> Engine:
    """An engine for url; SQLite files get their folder and WAL mode. Raises DatabaseError."""
    try:
        parsed = make_url(normalise(url))
    except ArgumentError as err:
        raise DatabaseError(f"--db {url!r}: not a database URL ({err})") from err
    backend = parsed.get_backend_name()
    if backend == "sqlite":
        if not parsed.database or parsed.database == ":memory:":
            raise DatabaseError(f"--db {url!r}: give a file (sqlite:///PATH); memory is not kept")
        Path(parsed.database).parent.mkdir(parents=True, exist_ok=True)
        engine = create_engine(parsed, connect_args={"check_same_thread": False})
        event.listen(engine, "connect", _sqlite_pragmas)
    elif backend == "postgresql":
        engine = create_engine(parsed, pool_size=8, max_overflow=8, pool_pre_ping=True)
    else:
        raise DatabaseError(
            f"--db {url!r}: backend '{backend}' is not supported (sqlite, postgresql)"
        )
    try:
        with engine.connect():
            pass
    except (OperationalError, SQLAlchemyError) as err:
        first = str(err).strip().splitlines()[0]
        raise DatabaseError(f"--db {url!r}: cannot connect ({first})") from err
    return engine


def migrate(engine: Engine) -> None:
    """Brings the schema to the newest Alembic revision (the scripts in migrations/versions)."""
    cfg = Config()
    cfg.set_main_option("script_location", str(MIGRATIONS))
    with engine.begin() as conn:
        cfg.attributes["connection"] = conn
        command.upgrade(cfg, "head")


def sessions(engine: Engine) -> sessionmaker[Session]:
    return sessionmaker(engine, expire_on_commit=False)
