"""Users, passwords and sessions of the SCM. Passwords are stored as argon2id hashes
(argon2-cffi); a session is a signed cookie (itsdangerous through Starlette's SessionMiddleware,
SameSite=strict) holding the user, the role and a CSRF token that every change must echo in the
X-CSRF-Token header."""

from __future__ import annotations

import secrets
import time

from argon2 import PasswordHasher
from argon2.exceptions import InvalidHashError, VerificationError
from sqlalchemy.orm import Session, sessionmaker

from autodrive.scm.models import Setting, User

ROLES = ("operator", "viewer")
_hasher = PasswordHasher()


class UserError(ValueError):
    pass


def add_user(sessions: sessionmaker[Session], name: str, role: str, password: str) -> bool:
    """Adds a user or sets an existing one's role and password; True when it is new."""
    if role not in ROLES:
        raise UserError(f"--role must be one of {list(ROLES)}, got {role!r}")
    if not name or len(name) > 64 or not name.replace("_", "").replace("-", "").isalnum():
        raise UserError(f"user name {name!r}: 1..64 letters, digits, '-' or '_'")
    if len(password) < 8:
        raise UserError("the password must have at least 8 characters")
    with sessions() as s, s.begin():
        user = s.get(User, name)
        if user is None:
            s.add(
                User(
                    name=name,
                    role=role,
                    password_hash=_hasher.hash(password),
                    created_us=int(time.time() * 1e6),
                )
            )
            return True
        user.role, user.password_hash = role, _hasher.hash(password)
        return False


def check_login(sessions: sessionmaker[Session], name: str, password: str) -> User | None:
    with sessions() as s:
        user = s.get(User, name)
        if user is None:
            _hasher.hash(password)  # the same work whether or not the user exists
            return None
        try:
            _hasher.verify(user.password_hash, password)
        except (VerificationError, InvalidHashError):
            return None
        return user


def session_secret(sessions: sessionmaker[Session]) -> str:
    """The cookie-signing secret, made once and kept in the database (settings table)."""
    with sessions() as s, s.begin():
        row = s.get(Setting, "session_secret")
        if row is None:
            row = Setting(key="session_secret", value=secrets.token_urlsafe(48))
            s.add(row)
        return row.value
