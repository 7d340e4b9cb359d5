"""Signed commands, the Python side: the same canonical bytes and truncated HMAC-SHA-256 as
the C++ signer (<autodrive/command_auth.hpp>); the byte order is documented once, in
lcm_types/autodrive/vehicle_command_t.lcm, and tests/foundation/command_auth_vectors.json holds
the vectors both must match. Every Python program that publishes <VEH>_COMMAND signs with
`Signer`; keys are made by `autodrive.core.keys` (tools/keys)."""

from __future__ import annotations

import hashlib
import hmac
import os
import secrets
import stat
import struct
import time
from pathlib import Path
from typing import Any

KEY_BYTES = 32
MAC_BYTES = 16
MAX_SOURCE_CHARS = 32
MAGIC = b"ADCMD1"
AUTHORITY_MACHINE = 1
AUTHORITY_PERSON = 2


def default_key_path(vehicle: str) -> Path:
    """$AUTODRIVE_KEY_DIR/<VEH>.key, else $XDG_CONFIG_HOME (or ~/.config)/autodrive/keys/<VEH>.key."""
    key_dir = os.environ.get("AUTODRIVE_KEY_DIR")
    if key_dir:
        return Path(key_dir) / f"{vehicle}.key"
    base = os.environ.get("XDG_CONFIG_HOME") or str(Path.home() / ".config")
    return Path(base) / "autodrive" / "keys" / f"{vehicle}.key"


def create_key(path: Path, force: bool = False) -> None:
    """Writes a new random key (64 hex digits) to path with mode 0600. ValueError naming the
    file if it exists and force is False."""
    if path.exists() and not force:
        raise ValueError(f"{path}: a key exists already (--force replaces it)")
    path.parent.mkdir(parents=True, exist_ok=True, mode=0o700)
    tmp = path.with_name(path.name + ".tmp")
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o600)
    with os.fdopen(fd, "w") as f:
        f.write(secrets.token_hex(KEY_BYTES) + "\n")
    os.chmod(tmp, 0o600)
    os.replace(tmp, path)


def load_key(path: Path) -> bytes:
    """The 32-byte key of a key file; ValueError naming the file when it is missing, readable by
    group or others, or not 64 hex digits (the bridge refuses the same files)."""
    try:
        mode = path.stat().st_mode
    except FileNotFoundError:
        raise ValueError(
            f"{path}: command key file missing (create it with tools/keys create)"
        ) from None
    if mode & (stat.S_IRWXG | stat.S_IRWXO):
        raise ValueError(
            f"{path}: command key file is readable by group or others "
            f"(mode {oct(mode & 0o777)[2:]}); chmod 600 it"
        )
    words = path.read_text().split()
    if len(words) != 1 or len(words[0]) != 2 * KEY_BYTES:
        raise ValueError(f"{path}: command key file must hold 64 hex digits (32 bytes) on one line")
    try:
        return bytes.fromhex(words[0])
    except ValueError:
        raise ValueError(
            f"{path}: command key file must hold 64 hex digits (32 bytes) on one line"
        ) from None


def _str(s: str) -> bytes:
    b = s.encode("ascii", "replace")[:255]
    return bytes([len(b)]) + b


def canonical_bytes(cmd: Any, vehicle: str) -> bytes:
    """The bytes the MAC covers (see vehicle_command_t.lcm); cmd is a vehicle_command_t."""
    return b"".join(
        (
            MAGIC,
            _str(vehicle),
            _str(cmd.source),
            struct.pack(
                ">bqqiffbbB",
                cmd.authority,
                cmd.counter,
                cmd.utime,
                cmd.seq,
                cmd.throttle,
                cmd.steering,
                cmd.headlights,
                cmd.indicators,
                1 if cmd.engaged else 0,
            ),
        )
    )


def mac_of(key: bytes, message: bytes) -> bytes:
    """HMAC-SHA-256(key, message) truncated to 16 bytes."""
    return hmac.new(key, message, hashlib.sha256).digest()[:MAC_BYTES]


def source_problem(source: str) -> str:
    """'' when the source id is usable, else what is wrong with it."""
    if not source:
        return "empty source id"
    if len(source) > MAX_SOURCE_CHARS:
        return f"source id longer than {MAX_SOURCE_CHARS} characters"
    if any(not 0x21 <= ord(ch) <= 0x7E for ch in source):
        return "source id has a character that is not printable ASCII"
    return ""


class Signer:
    """Fills source, authority, counter (wall clock [us], strictly increasing) and mac."""

    def __init__(self, key: bytes, vehicle: str, source: str, authority: int) -> None:
        why = source_problem(source)
        if why:
            raise ValueError(f"command signer: source {source!r}: {why}")
        if authority not in (AUTHORITY_MACHINE, AUTHORITY_PERSON):
            raise ValueError(f"command signer: authority {authority} is not 1 or 2")
        if len(key) != KEY_BYTES:
            raise ValueError(f"command signer: the key has {len(key)} bytes, not {KEY_BYTES}")
        self.key, self.vehicle, self.source, self.authority = key, vehicle, source, authority
        self._last = 0

    def sign(self, cmd: Any) -> Any:
        """Signs cmd in place and returns it."""
        cmd.source = self.source
        cmd.authority = self.authority
        self._last = max(self._last + 1, time.time_ns() // 1000)
        cmd.counter = self._last
        # Floats go through float32, as the wire carries them, before the MAC is taken.
        cmd.throttle = struct.unpack(">f", struct.pack(">f", cmd.throttle))[0]
        cmd.steering = struct.unpack(">f", struct.pack(">f", cmd.steering))[0]
        cmd.mac = mac_of(self.key, canonical_bytes(cmd, self.vehicle))
        return cmd


def signer_for(vehicle: str, source: str, authority: int = AUTHORITY_MACHINE) -> Signer:
    """A signer with the car's key from its default place; ValueError naming the file."""
    return Signer(load_key(default_key_path(vehicle)), vehicle, source, authority)
