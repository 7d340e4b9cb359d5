"""The Python command signer against the shared test vectors (the C++ signer checks the same
file: runtime.unit.CommandAuth.*), the keys tool (mode 0600, no silent overwrite, refuses
group-readable keys), and tools/lcm-route's decision on a host with a default route (a fake
`ip` on PATH records what it would change)."""

from __future__ import annotations

import json
import os
import pathlib
import stat
import subprocess
import types

import pytest

from autodrive.core import command_auth
from autodrive.core import keys


def vectors(root: pathlib.Path) -> list[dict]:
    return json.loads((root / "tests" / "foundation" / "command_auth_vectors.json").read_text())[
        "vectors"
    ]


def test_signer_matches_shared_vectors(root: pathlib.Path) -> None:
    for v in vectors(root):
        cmd = types.SimpleNamespace(**v["cmd"])
        m = command_auth.canonical_bytes(cmd, v["vehicle"])
        assert m.hex() == v["canonical_hex"], f"canonical bytes differ for {v['cmd']['source']}"
        mac = command_auth.mac_of(bytes.fromhex(v["key"]), m)
        assert mac.hex() == v["mac_hex"], f"MAC differs for {v['cmd']['source']}"
        # The Signer gives the same MAC for the same fields and counter.
        s = command_auth.Signer(bytes.fromhex(v["key"]), v["vehicle"], cmd.source, cmd.authority)
        s._last = cmd.counter - 1 - 10**18  # the counter is the wall clock: reproduce it exactly
        signed = s.sign(types.SimpleNamespace(**v["cmd"]))
        signed.counter = cmd.counter
        signed.mac = command_auth.mac_of(s.key, command_auth.canonical_bytes(signed, s.vehicle))
        assert signed.mac == mac
    print(f"{len(vectors(root))} test vectors: canonical bytes and MACs agree")


def test_counters_increase_and_sources_checked(root: pathlib.Path) -> None:
    # Counters strictly increase, even when the clock does not move.
    s = command_auth.Signer(b"k" * 32, "NIGEL1", "t", command_auth.AUTHORITY_MACHINE)
    c1 = s.sign(types.SimpleNamespace(**vectors(root)[0]["cmd"]))
    n1 = c1.counter
    c2 = s.sign(types.SimpleNamespace(**vectors(root)[0]["cmd"]))
    assert c2.counter > n1
    for bad in ("", "x" * 33, "a b"):
        try:
            command_auth.Signer(b"k" * 32, "NIGEL1", bad, command_auth.AUTHORITY_MACHINE)
            raise AssertionError(f"source {bad!r} accepted")
        except ValueError:
            pass


def test_keys_tool(tmp_path: pathlib.Path, monkeypatch: pytest.MonkeyPatch) -> None:
    tmp = str(tmp_path)
    monkeypatch.setenv("AUTODRIVE_KEY_DIR", tmp)
    assert keys.main(["create", "NIGEL7"]) == 0
    path = pathlib.Path(tmp) / "NIGEL7.key"
    assert stat.S_IMODE(path.stat().st_mode) == 0o600, oct(path.stat().st_mode)
    key = command_auth.load_key(path)
    assert len(key) == 32
    assert keys.main(["create", "NIGEL7"]) == 1, "an existing key was overwritten"
    assert command_auth.load_key(path) == key
    assert keys.main(["create", "--if-missing", "NIGEL7"]) == 0
    assert command_auth.load_key(path) == key
    assert keys.main(["create", "--force", "NIGEL7"]) == 0
    assert command_auth.load_key(path) != key
    os.chmod(path, 0o640)
    try:
        command_auth.load_key(path)
        raise AssertionError("a group-readable key was accepted")
    except ValueError as e:
        assert str(path) in str(e) and "group or others" in str(e), e
    assert keys.main(["check", "NIGEL7"]) == 1
    print("keys tool: mode 0600, no silent overwrite, group-readable keys refused")


def test_lcm_route_keeps_bus_on_lo(root: pathlib.Path, tmp_path: pathlib.Path) -> None:
    fake = tmp_path
    (fake / "ip").write_text(
        """#!/usr/bin/env bash
# A host with a default route: the group goes out of eth0 until 239.0.0.0/8 dev lo is added.
echo "$*" >> "$FAKE_IP_LOG"
if [ "$1 $2" = "route get" ]; then
  if grep -q "route replace 239.0.0.0/8 dev lo" "$FAKE_IP_LOG"; then
    echo "multicast 239.255.76.67 dev lo table local src 127.0.0.1"
  else
    echo "multicast 239.255.76.67 dev eth0 src 192.0.2.2"
  fi
fi
exit 0
"""
    )
    (fake / "ip").chmod(0o755)
    (fake / "sudo").write_text('#!/usr/bin/env bash\nexec "$@"\n')
    (fake / "sudo").chmod(0o755)

    def route(action: str, **env: str) -> tuple[int, str, str]:
        log = fake / f"ip-{action}-{len(env)}.log"
        log.write_text("")
        e = dict(os.environ, PATH=f"{fake}:{os.environ['PATH']}", FAKE_IP_LOG=str(log), **env)
        e.pop("AUTODRIVE_LCM_MULTI_MACHINE", None) if not env else None
        r = subprocess.run(
            [str(root / "tools" / "lcm-route"), action], env=e, capture_output=True, text=True
        )
        return r.returncode, r.stdout + r.stderr, log.read_text()

    code, out, calls = route("check")
    assert code == 1 and "eth0" in out, out
    assert "route replace" not in calls, "check changed the routes"
    code, out, calls = route("ensure")
    assert code == 0, out
    assert "route replace 239.0.0.0/8 dev lo" in calls, calls
    assert "routed through lo" in out, out
    code, out, calls = route("ensure", AUTODRIVE_LCM_MULTI_MACHINE="1")
    assert code == 0 and "multi-machine" in out and "signed" in out, out
    assert "route replace" not in calls, "multi-machine use must leave the routes alone"
    setup = (root / "tools" / "setup").read_text()
    assert '"$ROOT/tools/lcm-route" ensure' in setup, "tools/setup does not keep LCM on lo"
    assert "autodrive.core.keys create --if-missing" in setup, "tools/setup creates no key"
    print("lcm-route: a default route gets 239.0.0.0/8 dev lo; multi-machine only when asked")
    print("command auth ok")
