"""The testbed's certificates and revocation list (Ed25519 via PyNaCl = libsodium), the Python
side of <autodrive_v2x/v2x_auth.h>. The byte layouts are documented once, in
docs/design/threat-model.md#certificates; tests/foundation/test_v2x_vectors.py holds vectors
that the C library must match.

Certificate (all integers big-endian), base64 on one line in a `.cert` file:
    "ADCRT1" | serial u64 | role u8 | name_len u8 | name (ASCII) | not_before i64 [unix s]
    | not_after i64 [unix s] | public key (32) | CA signature (64) over every byte before it
Revocation list (`ca.crl`, base64 on one line):
    "ADCRL1" | issued i64 [unix s] | count u32 | serial u64 * count | CA signature (64)
"""

from __future__ import annotations

import base64
import os
import struct
from dataclasses import dataclass
from pathlib import Path

import nacl.exceptions
import nacl.signing

CERT_MAGIC = b"ADCRT1"
CRL_MAGIC = b"ADCRL1"
PUBLIC_KEY_BYTES = 32
SIGNATURE_BYTES = 64
MAX_NAME_CHARS = 32
# Role numbers on the wire; the names are what tools/keys issue --role takes.
ROLES = {"car": 1, "scm": 2, "eye": 3, "light-controller": 4, "operator": 5}
ROLE_NAMES = {v: k for k, v in ROLES.items()}
_FIXED = struct.Struct(">QBB")  # serial, role, name_len
_VALIDITY = struct.Struct(">qq")  # not_before, not_after [unix s]


class CertificateError(ValueError):
    """A certificate or revocation list that is malformed or does not check out; the message
    names the input and what is wrong."""


@dataclass(frozen=True)
class Certificate:
    serial: int
    role: str
    name: str
    not_before_s: int  # unix time [s]
    not_after_s: int  # unix time [s]
    public_key: bytes  # Ed25519, 32 bytes
    signature: bytes  # the CA's, over body()

    def body(self) -> bytes:
        """The bytes the CA signs."""
        name = self.name.encode("ascii")
        return b"".join(
            (
                CERT_MAGIC,
                _FIXED.pack(self.serial, ROLES[self.role], len(name)),
                name,
                _VALIDITY.pack(self.not_before_s, self.not_after_s),
                self.public_key,
            )
        )

    def encode(self) -> bytes:
        return self.body() + self.signature


def name_problem(name: str) -> str:
    """'' when name is a usable certificate name (1-32 printable ASCII, no space), else why."""
    if not 1 <= len(name) <= MAX_NAME_CHARS:
        return f"name must have 1 to {MAX_NAME_CHARS} characters"
    if any(not 0x21 <= ord(ch) <= 0x7E for ch in name):
        return "name has a character that is not printable ASCII"
    return ""


def decode_certificate(data: bytes, what: str = "certificate") -> Certificate:
    """The certificate in data (raw bytes); CertificateError naming `what` when malformed. Does
    not check the signature: verify_certificate does."""
    head = len(CERT_MAGIC) + _FIXED.size
    if len(data) < head or data[: len(CERT_MAGIC)] != CERT_MAGIC:
        raise CertificateError(f"{what}: malformed certificate (no ADCRT1 header)")
    serial, role, name_len = _FIXED.unpack_from(data, len(CERT_MAGIC))
    need = head + name_len + _VALIDITY.size + PUBLIC_KEY_BYTES + SIGNATURE_BYTES
    if len(data) != need:
        raise CertificateError(
            f"{what}: malformed certificate ({len(data)} bytes, its header says {need})"
        )
    if role not in ROLE_NAMES:
        raise CertificateError(f"{what}: malformed certificate (unknown role number {role})")
    try:
        name = data[head : head + name_len].decode("ascii")
    except UnicodeDecodeError:
        raise CertificateError(f"{what}: malformed certificate (name is not ASCII)") from None
    why = name_problem(name)
    if why:
        raise CertificateError(f"{what}: malformed certificate ({why})")
    at = head + name_len
    not_before, not_after = _VALIDITY.unpack_from(data, at)
    at += _VALIDITY.size
    key = data[at : at + PUBLIC_KEY_BYTES]
    sig = data[at + PUBLIC_KEY_BYTES :]
    return Certificate(serial, ROLE_NAMES[role], name, not_before, not_after, key, sig)


def verify_certificate(cert: Certificate, ca_public_key: bytes, now_s: float) -> None:
    """CertificateError naming the certificate when it is not signed by the CA, or not valid
    at now_s (unix time [s])."""
    who = f"certificate {cert.name} (serial {cert.serial})"
    try:
        nacl.signing.VerifyKey(ca_public_key).verify(cert.body(), cert.signature)
    except nacl.exceptions.BadSignatureError:
        raise CertificateError(f"{who}: unknown authority (not signed by this CA)") from None
    if now_s < cert.not_before_s:
        raise CertificateError(f"{who}: not yet valid (from unix {cert.not_before_s} s)")
    if now_s > cert.not_after_s:
        raise CertificateError(f"{who}: expired (at unix {cert.not_after_s} s)")


@dataclass(frozen=True)
class RevocationList:
    issued_s: int  # unix time [s]
    serials: frozenset[int]

    def body(self) -> bytes:
        ordered = sorted(self.serials)
        return (
            CRL_MAGIC
            + struct.pack(">qI", self.issued_s, len(ordered))
            + b"".join(struct.pack(">Q", s) for s in ordered)
        )


def decode_revocation_list(data: bytes, ca_public_key: bytes, what: str) -> RevocationList:
    """The revocation list in data, checked against the CA; CertificateError naming `what`."""
    head = len(CRL_MAGIC) + 12
    if len(data) < head + SIGNATURE_BYTES or data[: len(CRL_MAGIC)] != CRL_MAGIC:
        raise CertificateError(f"{what}: malformed revocation list (no ADCRL1 header)")
    issued, count = struct.unpack_from(">qI", data, len(CRL_MAGIC))
    if len(data) != head + 8 * count + SIGNATURE_BYTES:
        raise CertificateError(f"{what}: malformed revocation list (length does not match count)")
    body, sig = data[:-SIGNATURE_BYTES], data[-SIGNATURE_BYTES:]
    try:
        nacl.signing.VerifyKey(ca_public_key).verify(body, sig)
    except nacl.exceptions.BadSignatureError:
        raise CertificateError(f"{what}: revocation list not signed by this CA") from None
    serials = frozenset(struct.unpack_from(f">{count}Q", data, head))
    return RevocationList(issued, serials)


def read_b64_file(path: Path, what: str) -> bytes:
    """The bytes of a one-line base64 file; CertificateError naming the file."""
    try:
        text = path.read_text().strip()
    except OSError as e:
        raise CertificateError(f"{path}: cannot read the {what} ({e.strerror})") from None
    try:
        return base64.b64decode(text, validate=True)
    except ValueError:
        raise CertificateError(f"{path}: the {what} is not one line of base64") from None


def write_private(path: Path, text: str) -> None:
    """Writes text to path with mode 0600 (atomically: a reader never sees half a file)."""
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    tmp = path.with_name(path.name + ".tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.chmod(tmp, 0o600)
    os.replace(tmp, path)


def b64(data: bytes) -> str:
    return base64.b64encode(data).decode("ascii") + "\n"
