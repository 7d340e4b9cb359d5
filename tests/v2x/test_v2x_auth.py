"""The testbed CA and the signed envelope: every refusal names the sender and its reason, and
the C library (libautodrive_v2x_auth.so, the real one of this build) and the Python side accept
each other's messages and refuse the same forgeries. Each test makes its own CA in a temp dir."""

from __future__ import annotations

import base64
import ctypes
import os
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

import pytest

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.v2x_cert import CertificateError

NOW_US = 1_000_000_000  # the receiver's clock in these tests (think: sim time) [us]
ROOT = Path(__file__).resolve().parents[2]


@pytest.fixture(autouse=True)
def types(build_dir: Path) -> Any:
    return lcmtypes.load(build_dir)


@pytest.fixture()
def ca(tmp_path: Path) -> v2x_ca.Authority:
    authority = v2x_ca.Authority(tmp_path)
    authority.init()
    for name, role in (("NIGEL1", "car"), ("NIGEL2", "car"), ("SCM", "scm"), ("EYE1", "eye")):
        authority.issue(name, role, 1)
    return authority


def advisory(vehicle: str = "NIGEL1", light_state: int = 3) -> Any:
    msg = lcmtypes.load("").v2i_advisory_t()
    msg.utime, msg.vehicle, msg.light_state, msg.sign_kind = NOW_US, vehicle, light_state, ""
    return msg


def v2v(vehicle: str) -> Any:
    msg = lcmtypes.load("").v2v_state_t()
    msg.utime, msg.vehicle, msg.route, msg.x_m = NOW_US, vehicle, "", 1.5
    return msg


def signed(ca: v2x_ca.Authority, name: str, msg: Any, channel: str, utime: int = NOW_US,
           issued_s: float | None = None) -> Any:  # fmt: skip
    identity = v2x_ca.load_identity(name, ca.key_dir, issued_s)
    return v2x_auth.MessageSigner(identity).sign(channel, msg, utime)


def verdict(ca: v2x_ca.Authority, msg: Any, channel: str = "NIGEL1_V2I", channel_id: str = "V2I",
            name: str | None = None, now_us: int = NOW_US,
            verifier: v2x_auth.Verifier | None = None) -> v2x_auth.Verdict:  # fmt: skip
    v = verifier or v2x_auth.Verifier(ca.key_dir)
    return v.verify(channel, msg, v2x_auth.roles_for(channel_id), name, now_us)


def test_accepts_a_signed_advisory_and_counts_it(ca: v2x_ca.Authority) -> None:
    v = v2x_auth.Verifier(ca.key_dir)
    got = verdict(ca, signed(ca, "SCM", advisory(), "NIGEL1_V2I"), verifier=v)
    assert got.ok and got.sender == "SCM"
    assert v.counts[v2x_auth.ACCEPTED] == 1


def test_unsigned_is_refused(ca: v2x_ca.Authority) -> None:
    got = verdict(ca, advisory())
    assert got.reason == v2x_auth.UNSIGNED
    assert "unknown sender: unsigned" in got.describe("NIGEL1_V2I")


def test_forged_green_is_refused_naming_the_sender(ca: v2x_ca.Authority) -> None:
    msg = signed(ca, "SCM", advisory(light_state=1), "NIGEL1_V2I")
    msg.light_state = 3  # RED turned GREEN after signing
    got = verdict(ca, msg)
    assert got.reason == v2x_auth.BAD_SIGNATURE
    assert got.describe("NIGEL1_V2I").startswith("NIGEL1_V2I: dropped a message from sender SCM")


def test_another_channel_is_a_forgery(ca: v2x_ca.Authority) -> None:
    msg = signed(ca, "SCM", advisory(), "NIGEL2_V2I")
    assert verdict(ca, msg).reason == v2x_auth.BAD_SIGNATURE


def test_replay_is_refused_at_once_and_a_second_late(ca: v2x_ca.Authority) -> None:
    v = v2x_auth.Verifier(ca.key_dir)
    msg = signed(ca, "NIGEL2", v2v("NIGEL2"), "V2V")
    assert verdict(ca, msg, "V2V", "V2V", "NIGEL2", verifier=v).ok
    assert verdict(ca, msg, "V2V", "V2V", "NIGEL2", verifier=v).reason == v2x_auth.REPLAYED
    late = verdict(ca, msg, "V2V", "V2V", "NIGEL2", now_us=NOW_US + 1_000_000, verifier=v)
    assert late.reason == v2x_auth.STALE


def test_wrong_role_and_wrong_name(ca: v2x_ca.Authority) -> None:
    assert verdict(ca, signed(ca, "NIGEL1", advisory(), "NIGEL1_V2I")).reason == v2x_auth.WRONG_ROLE
    ghost = signed(ca, "NIGEL1", v2v("NIGEL2"), "V2V")  # NIGEL1 claims to be NIGEL2
    got = verdict(ca, ghost, "V2V", "V2V", "NIGEL2")
    assert got.reason == v2x_auth.WRONG_NAME and got.sender == "NIGEL1"


def test_revoked_takes_effect_on_reload(ca: v2x_ca.Authority) -> None:
    v = v2x_auth.Verifier(ca.key_dir)
    assert verdict(ca, signed(ca, "SCM", advisory(), "NIGEL1_V2I"), verifier=v).ok
    ca.revoke(["SCM"])
    v.reload()
    got = verdict(ca, signed(ca, "SCM", advisory(), "NIGEL1_V2I"), verifier=v)
    assert got.reason == v2x_auth.REVOKED and got.sender == "SCM"


def test_expired_and_not_yet_valid(ca: v2x_ca.Authority, tmp_path: Path) -> None:
    ca.issue("OLD", "scm", 1, now_s=1_000_000)
    with pytest.raises(CertificateError, match=r"certificate OLD \(serial \d+\): expired"):
        v2x_ca.load_identity("OLD", ca.key_dir)  # a sender finds out at its start
    old = signed(ca, "OLD", advisory(), "NIGEL1_V2I", issued_s=1_000_000)
    assert verdict(ca, old).reason == v2x_auth.EXPIRED
    ca.issue("LATER", "scm", 1, now_s=4_000_000_000)
    got = verdict(ca, signed(ca, "LATER", advisory(), "NIGEL1_V2I", issued_s=4_000_000_000))
    assert got.reason == v2x_auth.NOT_YET_VALID and got.sender == "LATER"


def test_unknown_authority(ca: v2x_ca.Authority, tmp_path: Path) -> None:
    other = v2x_ca.Authority(tmp_path / "other")
    other.init()
    other.issue("SCM", "scm", 1)
    msg = signed(other, "SCM", advisory(), "NIGEL1_V2I")
    assert verdict(ca, msg).reason == v2x_auth.UNKNOWN_AUTHORITY


def test_malformed_envelope_and_certificate(ca: v2x_ca.Authority) -> None:
    msg = signed(ca, "SCM", advisory(), "NIGEL1_V2I")
    good = bytes(msg.auth)
    for bad, reason in ((b"garbage", v2x_auth.MALFORMED_ENVELOPE),
                        (good[:-1], v2x_auth.MALFORMED_ENVELOPE),
                        (good[:8] + b"X" + good[9:], v2x_auth.MALFORMED_CERTIFICATE)):  # fmt: skip
        msg.auth, msg.auth_len = bad, len(bad)
        assert verdict(ca, msg).reason == reason


def test_malformed_certificate_file_names_the_file(ca: v2x_ca.Authority) -> None:
    (ca.key_dir / "SCM.cert").write_text(base64.b64encode(b"ADCRT1 short").decode())
    with pytest.raises(CertificateError, match="SCM.cert: malformed certificate"):
        v2x_ca.load_identity("SCM", ca.key_dir)
    (ca.key_dir / "SCM.cert").write_text("not base64 !!")
    with pytest.raises(CertificateError, match="SCM.cert: the certificate is not one line"):
        v2x_ca.load_identity("SCM", ca.key_dir)


def test_tools_keys_ca_cli(tmp_path: Path) -> None:
    def keys(*args: str) -> subprocess.CompletedProcess[str]:
        return subprocess.run([sys.executable, "-m", "autodrive.core.keys", "--dir",
                               str(tmp_path), *args], capture_output=True, text=True)  # fmt: skip

    assert keys("ca", "init").returncode == 0
    assert keys("issue", "--name", "NIGEL3", "--role", "car", "--days", "2").returncode == 0
    assert (tmp_path / "NIGEL3.sk").stat().st_mode & 0o077 == 0
    assert "ok" in keys("show", "NIGEL3").stdout
    assert keys("revoke", "NIGEL3").returncode == 0
    assert "REVOKED" in keys("show", "NIGEL3").stdout
    bad = keys("issue", "--name", "bad name", "--role", "car")
    assert bad.returncode == 1 and "printable ASCII" in bad.stderr


# --- the C library, through ctypes -------------------------------------------------------


class CLib:
    def __init__(self, build_dir: Path) -> None:
        self.lib = ctypes.CDLL(str(build_dir / "lib" / "libautodrive_v2x_auth.so"))
        self.lib.v2x_verifier_create.restype = ctypes.c_void_p
        self.lib.v2x_signer_load.restype = ctypes.c_void_p
        self.lib.v2x_reason_name.restype = ctypes.c_char_p
        self.lib.v2x_role_mask.restype = ctypes.c_uint
        self.lib.v2x_verify.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p,
            ctypes.c_size_t, ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_char_p,
            ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p]  # fmt: skip
        self.lib.v2x_sign.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p,
            ctypes.c_size_t, ctypes.c_int64, ctypes.c_char_p, ctypes.c_size_t]  # fmt: skip
        self.lib.v2x_sign.restype = ctypes.c_size_t
        self.lib.v2x_verifier_reload.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t]
        self.lib.v2x_verifier_destroy.argtypes = [ctypes.c_void_p]
        self.lib.v2x_signer_destroy.argtypes = [ctypes.c_void_p]

    def verifier(self, key_dir: Path) -> int:
        err = ctypes.create_string_buffer(512)
        v = self.lib.v2x_verifier_create(str(key_dir).encode(), err, 512)
        assert v, err.value.decode()
        return int(v)

    def verify(self, v: int, channel: str, msg: Any, roles: str, name: str | None,
               now_us: int = NOW_US) -> str:  # fmt: skip
        payload = v2x_auth.unsigned_payload(msg)
        auth = v2x_auth.auth_of(msg)
        r = self.lib.v2x_verify(v, channel.encode(), payload, len(payload), auth, len(auth),
                                self.lib.v2x_role_mask(roles.encode()),
                                name.encode() if name else None, now_us, int(time.time()), None)  # fmt: skip
        return str(self.lib.v2x_reason_name(r).decode())


@pytest.fixture()
def clib(build_dir: Path) -> CLib:
    return CLib(build_dir)


def test_c_verifier_agrees_with_python(ca: v2x_ca.Authority, clib: CLib) -> None:
    v = clib.verifier(ca.key_dir)
    msg = signed(ca, "SCM", advisory(), "NIGEL1_V2I")
    assert clib.verify(v, "NIGEL1_V2I", msg, "scm", None) == v2x_auth.ACCEPTED
    assert clib.verify(v, "NIGEL1_V2I", msg, "scm", None) == v2x_auth.REPLAYED
    assert clib.verify(v, "NIGEL1_V2I", advisory(), "scm", None) == v2x_auth.UNSIGNED
    ghost = signed(ca, "NIGEL1", v2v("NIGEL2"), "V2V")
    assert clib.verify(v, "V2V", ghost, "car", "NIGEL2") == v2x_auth.WRONG_NAME
    eye = signed(ca, "EYE1", advisory(), "NIGEL1_V2I")
    assert clib.verify(v, "NIGEL1_V2I", eye, "scm", None) == v2x_auth.WRONG_ROLE
    forged = signed(ca, "SCM", advisory(light_state=1), "NIGEL1_V2I")
    forged.light_state = 3
    assert clib.verify(v, "NIGEL1_V2I", forged, "scm", None) == v2x_auth.BAD_SIGNATURE
    late = signed(ca, "SCM", advisory(), "NIGEL1_V2I", utime=NOW_US - 1_000_000)
    assert clib.verify(v, "NIGEL1_V2I", late, "scm", None) == v2x_auth.STALE
    ca.revoke(["SCM"])
    os.utime(ca.crl_path, ns=(1, 2))  # a new mtime even on a coarse clock
    assert clib.lib.v2x_verifier_reload(v, None, 0) == 0
    again = signed(ca, "SCM", advisory(), "NIGEL1_V2I")
    assert clib.verify(v, "NIGEL1_V2I", again, "scm", None) == v2x_auth.REVOKED
    clib.lib.v2x_verifier_destroy(v)


def test_python_verifier_accepts_c_signed(ca: v2x_ca.Authority, clib: CLib) -> None:
    err = ctypes.create_string_buffer(512)
    s = clib.lib.v2x_signer_load(str(ca.key_dir).encode(), b"SCM", err, 512)
    assert s, err.value.decode()
    msg = advisory()
    payload = v2x_auth.unsigned_payload(msg)
    out = ctypes.create_string_buffer(256)
    n = clib.lib.v2x_sign(s, b"NIGEL1_V2I", payload, len(payload), NOW_US, out, 256)
    assert n > 0
    msg.auth, msg.auth_len = out.raw[:n], n
    assert verdict(ca, msg).ok
    clib.lib.v2x_signer_destroy(s)


def test_c_loader_names_a_bad_file(ca: v2x_ca.Authority, clib: CLib) -> None:
    (ca.key_dir / "SCM.sk").write_text("@@@")
    err = ctypes.create_string_buffer(512)
    assert not clib.lib.v2x_signer_load(str(ca.key_dir).encode(), b"SCM", err, 512)
    assert "SCM.sk: the private key is not one line of base64" in err.value.decode()
    (ca.ca_dir / "ca.pub").write_text("AAAA")
    assert not clib.lib.v2x_verifier_create(str(ca.key_dir).encode(), err, 512)
    assert "a CA public key has 32 bytes, this one 3" in err.value.decode()
