"""The testbed certificate authority: tools/keys ca init | issue | revoke | show.

Files (the key folder is $AUTODRIVE_KEY_DIR, else ~/.config/autodrive/keys; never the repo):
    ca/ca.key       the CA's Ed25519 seed (mode 0600; keep it off the cars)
    ca/ca.pub       the trust anchor every receiver loads (base64 of 32 bytes)
    ca/ca.crl       the revocation list, signed by the CA; the SCM serves it, receivers reload it
    ca/issued.txt   one line per certificate issued: serial name role not_after
    <NAME>.cert     a certificate (base64 on one line); <NAME>.sk its private seed (mode 0600)
"""

from __future__ import annotations

import argparse
import base64
import secrets
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import nacl.signing

from autodrive.core import channels
from autodrive.core.command_auth import create_key, default_key_path
from autodrive.core.v2x_cert import (
    ROLES,
    Certificate,
    CertificateError,
    RevocationList,
    b64,
    decode_certificate,
    decode_revocation_list,
    name_problem,
    read_b64_file,
    verify_certificate,
    write_private,
)

SECONDS_PER_DAY = 86400


def default_key_dir() -> Path:
    """The folder of the command keys, the CA (ca/) and the certificates."""
    return default_key_path("X").parent


@dataclass(frozen=True)
class Identity:
    """What a sender signs with: its certificate and the matching private key."""

    cert: Certificate
    signing_key: nacl.signing.SigningKey


class Authority:
    def __init__(self, key_dir: Path | None = None) -> None:
        self.key_dir = key_dir or default_key_dir()
        self.ca_dir = self.key_dir / "ca"

    @property
    def public_path(self) -> Path:
        return self.ca_dir / "ca.pub"

    @property
    def crl_path(self) -> Path:
        return self.ca_dir / "ca.crl"

    def init(self, force: bool = False) -> None:
        key_path = self.ca_dir / "ca.key"
        if key_path.exists() and not force:
            raise CertificateError(f"{key_path}: a CA exists already (--force replaces it)")
        key = nacl.signing.SigningKey.generate()
        write_private(key_path, b64(bytes(key)))
        write_private(self.public_path, b64(bytes(key.verify_key)))
        (self.ca_dir / "issued.txt").write_text("")
        self._write_crl(frozenset())

    def _signing_key(self) -> nacl.signing.SigningKey:
        path = self.ca_dir / "ca.key"
        if not path.exists():
            raise CertificateError(f"{path}: no CA here (make one with tools/keys ca init)")
        return nacl.signing.SigningKey(read_b64_file(path, "CA key"))

    def public_key(self) -> bytes:
        return load_trust_anchor(self.public_path)

    def issue(self, name: str, role: str, days: float, now_s: float | None = None) -> Path:
        """Makes NAME.cert and NAME.sk in the key folder; returns the certificate's path."""
        why = name_problem(name)
        if why:
            raise CertificateError(f"issue {name!r}: {why}")
        if role not in ROLES:
            raise CertificateError(f"issue {name}: unknown role {role!r} (one of {list(ROLES)})")
        if not days > 0:
            raise CertificateError(f"issue {name}: --days must be > 0, not {days}")
        ca = self._signing_key()
        now = int(time.time() if now_s is None else now_s)
        key = nacl.signing.SigningKey.generate()
        serial = secrets.randbits(63)
        unsigned = Certificate(
            serial, role, name, now - 60, now + int(days * SECONDS_PER_DAY),
            bytes(key.verify_key), b"",
        )  # fmt: skip
        cert = Certificate(**{**unsigned.__dict__, "signature": ca.sign(unsigned.body()).signature})
        write_private(self.key_dir / f"{name}.sk", b64(bytes(key)))
        cert_path = self.key_dir / f"{name}.cert"
        cert_path.write_text(b64(cert.encode()))
        with (self.ca_dir / "issued.txt").open("a") as f:
            f.write(f"{serial} {name} {role} {cert.not_after_s}\n")
        return cert_path

    def revoked(self) -> frozenset[int]:
        return load_revocation_list(self.crl_path, self.public_key()).serials

    def revoke(self, names_or_serials: list[str]) -> list[int]:
        """Adds the certificates (by name: every one issued to it; or by serial) to ca.crl."""
        issued = [line.split() for line in (self.ca_dir / "issued.txt").read_text().splitlines()]
        serials: list[int] = []
        for item in names_or_serials:
            hits = [int(row[0]) for row in issued if item in (row[0], row[1])]
            if not hits:
                raise CertificateError(f"revoke {item}: this CA issued no such name or serial")
            serials += hits
        self._write_crl(self.revoked() | frozenset(serials))
        return serials

    def _write_crl(self, serials: frozenset[int]) -> None:
        body = RevocationList(int(time.time()), serials).body()
        write_private(self.crl_path, b64(body + self._signing_key().sign(body).signature))
        self.crl_path.chmod(0o644)  # public: the SCM serves it


def load_trust_anchor(path: Path) -> bytes:
    key = read_b64_file(path, "CA public key")
    if len(key) != 32:
        raise CertificateError(f"{path}: a CA public key has 32 bytes, this one {len(key)}")
    return key


def load_revocation_list(path: Path, ca_public_key: bytes) -> RevocationList:
    return decode_revocation_list(read_b64_file(path, "revocation list"), ca_public_key, str(path))


def load_identity(name: str, key_dir: Path | None = None, now_s: float | None = None) -> Identity:
    """NAME.cert and NAME.sk from the key folder, checked against the CA there (valid at now_s,
    unix [s], default now) and each other; CertificateError naming the file."""
    folder = key_dir or default_key_dir()
    path = folder / f"{name}.cert"
    cert = decode_certificate(read_b64_file(path, "certificate"), str(path))
    verify_certificate(
        cert, Authority(folder).public_key(), time.time() if now_s is None else now_s
    )
    key = nacl.signing.SigningKey(read_b64_file(folder / f"{name}.sk", "private key"))
    if bytes(key.verify_key) != cert.public_key:
        raise CertificateError(f"{folder / (name + '.sk')}: not the key of {path}")
    return Identity(cert, key)


# The identities of a HIL run besides the cars: the Smart City Manager (and its stand-in), the
# Eye (and its stand-in), the simulator as the lights' controller.
TESTBED_IDENTITIES = (("SCM", "scm"), ("EYE", "eye"), ("SIM", "light-controller"))


def ensure_testbed(cars: list[str], key_dir: Path | None = None) -> list[Path]:
    """For setup, missions and tests: a CA and a certificate (30 days) for each car and each of
    TESTBED_IDENTITIES, each made only when missing or no longer valid; returns what it made.
    A lab issues its certificates by hand instead (tools/keys issue)."""
    ca = Authority(key_dir)
    if not (ca.ca_dir / "ca.key").exists() and not ca.public_path.exists():
        ca.init()
    made = []
    for name, role in [(c, "car") for c in cars] + list(TESTBED_IDENTITIES):
        try:
            if load_identity(name, ca.key_dir).cert.role == role:
                continue
        except CertificateError:
            pass  # missing, expired or broken: issued anew
        made.append(ca.issue(name, role, 30))
    return made


def ensure_run_keys(cars: list[str], say: Callable[[str], None]) -> None:
    """For a mission: each car's command key and the testbed certificates, made where missing
    in the key folder (say() tells what was made)."""
    for car in cars:
        path = default_key_path(car)
        if not path.exists():
            create_key(path)
            say(f"created the command key of {car} at {path} (tools/keys)")
    made = ensure_testbed(cars)
    if made:
        say(f"issued the testbed certificates {[p.name for p in made]} in {made[0].parent}")


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(
        prog="tools/keys",
        description="The testbed certificate authority: certificates (Ed25519) that sign V2V, "
        "V2I, light commands and states, and Eye poses. Folder: $AUTODRIVE_KEY_DIR, else "
        "~/.config/autodrive/keys (the CA in its ca/). Format: docs/design/threat-model.md.",
    )
    p.add_argument("--dir", type=Path, help="the key folder (default: see above)")
    sub = p.add_subparsers(dest="action", required=True)
    ca = sub.add_parser("ca", help="ca init: make the authority (ca/ca.key, ca/ca.pub, ca/ca.crl)")
    ca.add_argument("ca_action", choices=("init",))
    ca.add_argument("--force", action="store_true", help="replace an existing CA")
    issue = sub.add_parser("issue", help="issue a certificate: NAME.cert and NAME.sk")
    issue.add_argument("--name", required=True, help="e.g. NIGEL3, SCM, EYE1, SIM")
    issue.add_argument("--role", required=True, choices=list(ROLES))
    issue.add_argument("--days", type=float, default=30.0, help="validity [days] (default 30)")
    revoke = sub.add_parser("revoke", help="revoke certificates by name or serial (ca/ca.crl)")
    revoke.add_argument("items", nargs="+", help="names or serials")
    testbed = sub.add_parser(
        "testbed",
        help="a CA (if none) and certificates for the cars, SCM, EYE and SIM (if missing)",
    )
    testbed.add_argument("--cars", type=int, default=4, help="NIGEL1..NIGELn (default 4)")
    show = sub.add_parser("show", help="print and check certificates")
    show.add_argument("names", nargs="+")
    args = p.parse_args(argv)
    authority = Authority(args.dir)
    try:
        if args.action == "ca":
            authority.init(args.force)
            print(f"[keys] CA made in {authority.ca_dir} (trust anchor {authority.public_path})")
        elif args.action == "issue":
            path = authority.issue(args.name, args.role, args.days)
            print(f"[keys] issued {path} (role {args.role}, {args.days:g} days)")
        elif args.action == "testbed":
            cars = [channels.vehicle_name(i + 1) for i in range(args.cars)]
            made = ensure_testbed(cars, args.dir)
            print(
                f"[keys] testbed in {authority.key_dir}: made {[p.name for p in made] or 'nothing'}"
            )
        elif args.action == "revoke":
            serials = authority.revoke(args.items)
            print(f"[keys] revoked serials {serials}; {authority.crl_path} re-signed")
        else:
            revoked = authority.revoked()
            for name in args.names:
                ident = load_identity(name, args.dir)
                c = ident.cert
                state = "REVOKED" if c.serial in revoked else "ok"
                print(f"{name}: serial {c.serial} role {c.role} valid to unix {c.not_after_s} "
                      f"key {base64.b16encode(c.public_key[:8]).decode()}... {state}")  # fmt: skip
    except CertificateError as e:
        print(f"[keys] ERROR: {e}", file=sys.stderr)
        return 1
    return 0
