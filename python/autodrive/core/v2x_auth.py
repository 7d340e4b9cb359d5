"""Signed V2X messages, the Python side of <autodrive_v2x/v2x_auth.h> (the same bytes; the
layouts are documented once, in docs/design/threat-model.md#the-envelope).

A signed message type has `auth_len` and `auth` last (v2v_state_t, v2i_advisory_t,
traffic_light_command_t, traffic_light_state_t, pose2d_t); the signature covers the channel
and the LCM encoding of the message with an empty auth. Usage:

    signer = MessageSigner(v2x_ca.ensure_identity("SCM", "scm"))
    lc.publish(channel, signer.sign(channel, msg, sender_utime).encode())
    verifier = Verifier.from_key_dir()
    result = verifier.verify(channel, msg, roles_for("V2I"), None, now_us)
"""

from __future__ import annotations

import struct
import sys
import threading
import time
from collections import Counter
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import nacl.exceptions
import nacl.signing

from autodrive.core import channels
from autodrive.core.v2x_ca import Identity, default_key_dir, load_revocation_list, load_trust_anchor
from autodrive.core.v2x_cert import CertificateError, decode_certificate

ENVELOPE_MAGIC = b"ADSIG1"
DEFAULT_WINDOW_US = 500_000  # a message's sender time within this of the receiver's clock [us]


def roles_for(channel_id: str) -> frozenset[str]:
    """The roles that may sign a channel (its signed_by in lcm_types/channels.yaml)."""
    return frozenset(channels.load().by_id(channel_id).signed_by)


# Reasons, worded as the C library's v2x_reason_name.
ACCEPTED = "accepted"
UNSIGNED = "unsigned"
MALFORMED_ENVELOPE = "malformed envelope"
MALFORMED_CERTIFICATE = "malformed certificate"
UNKNOWN_AUTHORITY = "unknown authority"
NOT_YET_VALID = "certificate not yet valid"
EXPIRED = "certificate expired"
REVOKED = "certificate revoked"
WRONG_ROLE = "wrong role for this channel"
WRONG_NAME = "wrong name for this message"
BAD_SIGNATURE = "forged signature"
STALE = "stale (outside the time window)"
REPLAYED = "replayed (counter not newer)"


def signed_bytes(
    channel: str, serial: int, counter: int, sender_utime: int, payload: bytes
) -> bytes:
    ch = channel.encode("ascii")[:255]
    return (
        ENVELOPE_MAGIC
        + bytes([len(ch)])
        + ch
        + struct.pack(">QQq", serial, counter, sender_utime)
        + payload
    )


def auth_of(msg: Any) -> bytes:
    """msg.auth as bytes (a fresh generated message holds "")."""
    auth = msg.auth
    return auth.encode("latin-1") if isinstance(auth, str) else bytes(auth)


def unsigned_payload(msg: Any) -> bytes:
    """The LCM encoding of msg with an empty auth field (what the signature covers)."""
    auth = auth_of(msg)
    msg.auth_len, msg.auth = 0, b""
    try:
        return bytes(msg.encode())
    finally:
        msg.auth, msg.auth_len = auth, len(auth)


class MessageSigner:
    """Fills msg.auth with the envelope: certificate, counter, sender time, signature."""

    def __init__(self, identity: Identity) -> None:
        self.identity = identity
        self._cert = identity.cert.encode()
        self._counter = 0

    def envelope(self, channel: str, payload: bytes, sender_utime: int) -> bytes:
        # Strictly increasing across restarts too: at least the wall clock [us].
        self._counter = max(self._counter + 1, time.time_ns() // 1000)
        sig = self.identity.signing_key.sign(
            signed_bytes(channel, self.identity.cert.serial, self._counter, sender_utime, payload)
        ).signature
        return b"".join(
            (
                ENVELOPE_MAGIC,
                struct.pack(">H", len(self._cert)),
                self._cert,
                struct.pack(">Qq", self._counter, sender_utime),
                sig,
            )
        )

    def sign(self, channel: str, msg: Any, sender_utime: int) -> Any:
        """Signs msg in place (sender_utime: the sender's clock [us], sim time in HIL)."""
        msg.auth = self.envelope(channel, unsigned_payload(msg), sender_utime)
        msg.auth_len = len(msg.auth)
        return msg


@dataclass(frozen=True)
class Verdict:
    reason: str  # ACCEPTED or why refused
    sender: str  # the certificate's name, "" when none could be read
    serial: int = 0

    @property
    def ok(self) -> bool:
        return self.reason == ACCEPTED

    def describe(self, channel: str) -> str:
        who = f"sender {self.sender} (serial {self.serial})" if self.sender else "unknown sender"
        return f"{channel}: dropped a message from {who}: {self.reason}"


class Verifier:
    """Checks envelopes against the trust anchor and the revocation list, keeps each sender's
    last counter, and counts outcomes by reason (`counts`)."""

    def __init__(self, key_dir: Path | None = None, window_us: int = DEFAULT_WINDOW_US) -> None:
        self.key_dir = key_dir or default_key_dir()
        self.ca_public_key = load_trust_anchor(self.key_dir / "ca" / "ca.pub")
        self.window_us = window_us
        self.revoked: frozenset[int] = frozenset()
        self._crl_mtime = -1
        self._last_counter: dict[int, int] = {}
        self._checked_certs: set[bytes] = set()
        self.counts: Counter[str] = Counter()
        self.reload()

    def reload(self) -> None:
        """Re-reads ca/ca.crl when it changed; CertificateError naming it when it is bad (the
        list held so far stays in force)."""
        path = self.key_dir / "ca" / "ca.crl"
        mtime = path.stat().st_mtime_ns
        if mtime != self._crl_mtime:
            self.revoked = load_revocation_list(path, self.ca_public_key).serials
            self._crl_mtime = mtime

    def verify(
        self,
        channel: str,
        msg: Any,
        roles: frozenset[str],
        name: str | None,
        now_us: int,
        wall_s: float | None = None,
    ) -> Verdict:
        """The verdict on msg (now_us: the receiver's clock, sim time in HIL; wall_s: unix
        time for the certificate's validity, default now). Counted in `counts`."""
        verdict = self._check(channel, auth_of(msg), unsigned_payload(msg), roles, name,
                              now_us, time.time() if wall_s is None else wall_s)  # fmt: skip
        self.counts[verdict.reason] += 1
        return verdict

    def _check(
        self,
        channel: str,
        auth: bytes,
        payload: bytes,
        roles: frozenset[str],
        name: str | None,
        now_us: int,
        wall_s: float,
    ) -> Verdict:
        if not auth:
            return Verdict(UNSIGNED, "")
        head = len(ENVELOPE_MAGIC) + 2
        if len(auth) < head or auth[: len(ENVELOPE_MAGIC)] != ENVELOPE_MAGIC:
            return Verdict(MALFORMED_ENVELOPE, "")
        (cert_len,) = struct.unpack_from(">H", auth, len(ENVELOPE_MAGIC))
        if len(auth) != head + cert_len + 16 + 64:
            return Verdict(MALFORMED_ENVELOPE, "")
        cert_bytes = auth[head : head + cert_len]
        try:
            cert = decode_certificate(cert_bytes)
        except CertificateError:
            return Verdict(MALFORMED_CERTIFICATE, "")
        sender = (cert.name, cert.serial)
        if cert_bytes not in self._checked_certs:
            try:
                nacl.signing.VerifyKey(self.ca_public_key).verify(cert.body(), cert.signature)
            except nacl.exceptions.BadSignatureError:
                return Verdict(UNKNOWN_AUTHORITY, *sender)
            self._checked_certs.add(cert_bytes)
        if wall_s < cert.not_before_s:
            return Verdict(NOT_YET_VALID, *sender)
        if wall_s > cert.not_after_s:
            return Verdict(EXPIRED, *sender)
        if cert.serial in self.revoked:
            return Verdict(REVOKED, *sender)
        if cert.role not in roles:
            return Verdict(WRONG_ROLE, *sender)
        if name is not None and name != cert.name:
            return Verdict(WRONG_NAME, *sender)
        counter, sender_utime = struct.unpack_from(">Qq", auth, head + cert_len)
        try:
            nacl.signing.VerifyKey(cert.public_key).verify(
                signed_bytes(channel, cert.serial, counter, sender_utime, payload), auth[-64:]
            )
        except nacl.exceptions.BadSignatureError:
            return Verdict(BAD_SIGNATURE, *sender)
        if abs(now_us - sender_utime) > self.window_us:
            return Verdict(STALE, *sender)
        if counter <= self._last_counter.get(cert.serial, 0):
            return Verdict(REPLAYED, *sender)
        self._last_counter[cert.serial] = counter
        return Verdict(ACCEPTED, *sender)


class BusClock:
    """The clock a program without SIM_CLOCK of its own signs and checks with: the latest
    simulator time it heard (SIM_CLOCK, or a signed TRAFFIC_LIGHT_STATE's sender time; only
    forward), else this machine's wall clock (a real town, where every clock is the wall's).
    [us]"""

    def __init__(self) -> None:
        self.sim_us: int | None = None
        self._lock = threading.Lock()

    def heard(self, sim_us: int) -> None:
        with self._lock:
            self.sim_us = sim_us if self.sim_us is None else max(self.sim_us, sim_us)

    def now_us(self) -> int:
        with self._lock:
            return time.time_ns() // 1000 if self.sim_us is None else self.sim_us


def sender_utime(auth: bytes) -> int | None:
    """The sender time [us] an envelope claims (unchecked), None when malformed."""
    head = len(ENVELOPE_MAGIC) + 2
    if len(auth) < head:
        return None
    (cert_len,) = struct.unpack_from(">H", auth, len(ENVELOPE_MAGIC))
    if len(auth) != head + cert_len + 16 + 64:
        return None
    return int(struct.unpack_from(">q", auth, head + cert_len + 8)[0])


class DropLog:
    """Logs refused messages at a bounded rate: at most `burst` lines per `period_s` (on the
    caller's clock), then one summary line of what was dropped since."""

    def __init__(self, burst: int = 5, period_s: float = 10.0) -> None:
        self.burst, self.period_s = burst, period_s
        self._window_start = float("-inf")
        self._lines = 0
        self._suppressed = 0

    def log(self, line: str, now_s: float) -> None:
        if now_s - self._window_start >= self.period_s:
            if self._suppressed:
                print(f"[v2x] dropped {self._suppressed} more messages in the last "
                      f"{self.period_s:g} s", file=sys.stderr)  # fmt: skip
            self._window_start, self._lines, self._suppressed = now_s, 0, 0
        if self._lines < self.burst:
            self._lines += 1
            print(f"[v2x] {line}", file=sys.stderr)
        else:
            self._suppressed += 1
