"""Users, passwords and sessions of the SCM. Passwords are stored as argon2id hashes
(argon2-cffi); a session is a signed cookie (itsdangerous through Starlette's SessionMiddleware,
SameSite=strict) holding the user, the role and a CSRF token that every change must echo in the
X-CSRF-Token header. Logins are limited per account and per address (LoginLimiter); sessions
end when idle or old (session_expired)."""

from __future__ import annotations

import collections
import secrets
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass

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


# --- login limits ------------------------------------------------------------------------
ACCOUNT_FAILURES = 10  # failed logins in a row that lock an account [count]
ACCOUNT_LOCK_S = 900.0  # how long [s] (tries while locked are refused unchecked)
ADDRESS_FAILURES = 30  # failed logins from one address within ADDRESS_WINDOW_S [count]
ADDRESS_WINDOW_S = 60.0  # [s]
# A refused login answers this late (without holding a worker): a scripted guesser on one
# connection then costs the server a few percent, not the other users' response time.
LOGIN_REFUSED_DELAY_S = 0.05
SESSION_IDLE_S = 1800.0  # a session unused this long ends [s]
SESSION_MAX_S = 8 * 3600.0  # and any session this long after its login [s]


class LoginRefused(Exception):
    """A login refused before its password is checked: the account is locked or the address
    has failed too often. The message says which and for how long (HTTP 429)."""


@dataclass
class _Account:
    failures: int = 0
    locked_until_s: float = 0.0


class LoginLimiter:
    """Failed logins per account and per address. An account that fails ACCOUNT_FAILURES times
    in a row is locked for ACCOUNT_LOCK_S, whatever the address (a brute force of one account
    locks that account, not the others); an address with ADDRESS_FAILURES failures in
    ADDRESS_WINDOW_S may not try again until the window has passed. A refused try is decided
    before any password hash is computed, so a flood costs the server next to nothing. Times
    are this machine's monotonic clock (a security limit of the real server, not of a run)."""

    def __init__(self, clock: Callable[[], float] = time.monotonic) -> None:
        self.clock = clock
        self._lock = threading.Lock()
        self._accounts: dict[str, _Account] = {}
        self._address_failures: dict[str, collections.deque[float]] = {}

    def check(self, name: str, address: str) -> None:
        """LoginRefused when this try may not be checked at all."""
        now = self.clock()
        with self._lock:
            fails = self._address_failures.get(address)
            while fails and now - fails[0] > ADDRESS_WINDOW_S:
                fails.popleft()
            if fails is not None and len(fails) >= ADDRESS_FAILURES:
                wait = ADDRESS_WINDOW_S - (now - fails[0])
                raise LoginRefused(
                    f"too many failed logins from {address}: try again in {wait:.0f} s"
                )
            account = self._accounts.get(name)
            if account is not None and account.locked_until_s > now:
                raise LoginRefused(
                    f"account '{name}' is locked after {ACCOUNT_FAILURES} failed logins: "
                    f"try again in {account.locked_until_s - now:.0f} s"
                )

    def failed(self, name: str, address: str) -> None:
        now = self.clock()
        with self._lock:
            self._address_failures.setdefault(address, collections.deque()).append(now)
            account = self._accounts.setdefault(name, _Account())
            account.failures += 1
            if account.failures >= ACCOUNT_FAILURES:
                account.locked_until_s = now + ACCOUNT_LOCK_S

    def succeeded(self, name: str) -> None:
        with self._lock:
            self._accounts.pop(name, None)

    def locked(self, name: str) -> bool:
        with self._lock:
            account = self._accounts.get(name)
            return account is not None and account.locked_until_s > self.clock()


def session_expired(session: dict[str, object], now_s: float) -> str:
    """'' while a logged-in session is usable, else why it ended (idle or too old). now_s:
    unix time [s]; the session holds login_s and seen_s."""
    login_s, seen_s = session.get("login_s"), session.get("seen_s")
    if not isinstance(login_s, (int, float)) or not isinstance(seen_s, (int, float)):
        return "session without its times (from an older server): log in again"
    if now_s - login_s > SESSION_MAX_S:
        return f"session expired: {SESSION_MAX_S / 3600:g} h after its login"
    if now_s - seen_s > SESSION_IDLE_S:
        return f"session expired: unused for {SESSION_IDLE_S / 60:g} min"
    return ""
