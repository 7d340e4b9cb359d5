"""The SCM's web hardening on the real server over HTTPS (a self-signed certificate made here):
the session cookie is Secure, pages carry a Content-Security-Policy, a scripted brute force of
1,000 guesses (the right password among them) from its own address gets no session and locks
that account only, every refused request is in the event log; and the login limits and
session expiry on a clock passed in."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path
from typing import Any

from harness import check, wait_for
from autodrive.scm.core import security
from autodrive.scm.testkit import Attacker, Client, Server, add_user, self_signed_cert


def test_login_limiter_on_a_clock_passed_in() -> None:
    now = [0.0]
    limiter = security.LoginLimiter(clock=lambda: now[0])
    for _ in range(security.ACCOUNT_FAILURES):
        limiter.check("alice", "10.0.0.9")
        limiter.failed("alice", "10.0.0.9")
    check(limiter.locked("alice"), "alice is locked after ACCOUNT_FAILURES failures")
    try:
        limiter.check("alice", "10.0.0.1")
        check(False, "a locked account is refused from any address")
    except security.LoginRefused as e:
        check("account 'alice' is locked" in str(e), f"refusal names the account: {e}")
    limiter.check("bob", "10.0.0.1")  # others are not locked
    now[0] += security.ACCOUNT_LOCK_S + 1
    limiter.check("alice", "10.0.0.1")
    check(not limiter.locked("alice"), "the lock ends after ACCOUNT_LOCK_S")
    for i in range(security.ADDRESS_FAILURES):  # a spray over many accounts from one address
        limiter.failed(f"user{i}", "10.0.0.66")
    try:
        limiter.check("carol", "10.0.0.66")
        check(False, "an address over its limit is refused")
    except security.LoginRefused as e:
        check("too many failed logins from 10.0.0.66" in str(e), f"refusal names the address: {e}")
    limiter.check("carol", "10.0.0.1")


def test_session_expiry() -> None:
    s = {"user": "a", "login_s": 1000.0, "seen_s": 1000.0}
    check(security.session_expired(s, 1000.0 + 60) == "", "a fresh session is usable")
    idle = security.session_expired(s, 1000.0 + security.SESSION_IDLE_S + 1)
    check("unused for" in idle, f"an idle session ends: {idle}")
    s["seen_s"] = 1000.0 + security.SESSION_MAX_S
    old = security.session_expired(s, 1000.0 + security.SESSION_MAX_S + 1)
    check("after its login" in old, f"an old session ends: {old}")
    check("older server" in security.session_expired({"user": "a"}, 0.0), "no times: ended")


def test_https_server_under_brute_force(build_dir: Path, lcm_url: str) -> None:
    with tempfile.TemporaryDirectory(prefix="scm-harden-") as tmp:
        db = f"sqlite:///{Path(tmp) / 'scm.sqlite'}"
        add_user(db, "alice", "operator", "correct-horse-1")
        add_user(db, "bob", "operator", "battery-staple-2")
        cert, key = self_signed_cert(Path(tmp))
        server = Server(db, lcm_url, str(build_dir), tls=(cert, key))
        try:
            check(server.url.startswith("https://"), f"served over TLS: {server.url}")
            bob = Client(server.url, cafile=cert)
            bob.login("bob", "battery-staple-2")
            cookie = next(c for c in bob.cookies if c.name == "scm_session")
            check(cookie.secure, "the session cookie is Secure")
            code, _ = bob.call("GET", "/")
            csp = bob.last_headers.get("content-security-policy", "")
            check(code == 200 and "script-src 'self'" in csp, f"the page has a CSP: {csp}")
            check("frame-ancestors 'none'" in csp, "no framing")
            check("strict-transport-security" in bob.last_headers, "HSTS over TLS")

            guesses = [f"guess-{i}" for i in range(999)]
            guesses.insert(500, "correct-horse-1")  # the right one, while locked
            attacker = Attacker(server.url, cafile=cert)
            counts = attacker.brute_force("alice", guesses)
            attacker.close()
            print(f"brute force answers by status: {counts}", flush=True)
            check(counts.get(200, 0) == 0, "no guess of 1,000 got a session")
            check(counts.get(401, 0) == security.ACCOUNT_FAILURES, "10 were checked, then locked")
            check(counts.get(429, 0) == 1000 - security.ACCOUNT_FAILURES, "the rest refused: 429")
            code, _ = bob.call("GET", "/api/state")
            check(code == 200, "bob's session still works")
            carol = Client(server.url, cafile=cert)
            carol.login("bob", "battery-staple-2")  # another login of an unlocked account
            late = Client(server.url, cafile=cert)
            code, body = late.call(
                "POST", "/api/login", {"name": "alice", "password": "correct-horse-1"}
            )
            check(code == 429 and "locked" in body["detail"], f"alice is locked: {body}")

            def refused() -> list[dict[str, Any]]:
                _, events = bob.call("GET", "/api/events?limit=5000")
                return [e for e in events if e["kind"] == "request_refused"]

            # the log is written by the SCM's writer thread: wait until it has them all
            wait_for(lambda: len(refused()) >= 1000, 120, "every refused request is logged")
            details = [e["detail"] if isinstance(e["detail"], dict) else json.loads(e["detail"])
                       for e in refused()]  # fmt: skip
            check(sum(d.get("address") == "127.0.0.2" for d in details) >= 1000,
                  "naming the attacker's address")  # fmt: skip
            _, events = bob.call("GET", "/api/events?limit=5000")
            check(any(e["kind"] == "account_locked" and e["subject"] == "alice" for e in events),
                  "the lock is logged")  # fmt: skip
            anonymous = Client(server.url, cafile=cert)
            code, _ = anonymous.call("GET", "/api/state")
            check(code == 401, "no session: refused")
            code, crl = anonymous.call("GET", "/api/crl")
            check(code == 200 and crl.startswith(b"QURDUkwx"), "the revocation list is served")
        finally:
            server.stop()
