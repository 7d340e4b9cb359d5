"""LCM wire interop: PyPI lcm (Python bindings) <-> Debian LCM 1.3.1 (C++), over real UDP
multicast on loopback; and autodrive.core.lcm_wire's hand-read packets of the same bus (what
the C++ peer sent, with the kernel's receive time). Run by ctest with PYTHONPATH at the
generated Python bindings."""
import os
import select
import subprocess
import time
from typing import Callable

import lcm
from autodrive_msg import vehicle_command_t

from autodrive.core import lcm_wire

HANG_BACKSTOP_S = 120.0  # wall time [s]: against a hang only, never a pass/fail figure


def test_python_cpp_round_trips(program: Callable[[str], str], lcm_url: str) -> None:
    peer, url = program("lcm_echo_peer"), lcm_url
    count = 20
    proc = subprocess.Popen(
        [peer, url, "INTEROP_IN", "INTEROP_OUT", str(count)], stdout=subprocess.PIPE, text=True
    )
    assert proc.stdout.readline().strip() == "ready", "C++ peer did not start"

    lc = lcm.LCM(url)
    got = []
    tapped: list[tuple[bytes, int]] = []  # (payload, kernel receive time [us])
    tap = lcm_wire.WireTap(
        url, lambda ch, data, us: tapped.append((data, us)) if ch == "INTEROP_OUT" else None
    )
    sent_us: list[int] = []  # system clock before each publish
    read_us: list[int] = []  # ... and when the lcm library had handed its echo over
    lc.subscribe("INTEROP_OUT", lambda ch, data: got.append(vehicle_command_t.decode(data)))
    for i in range(count):
        m = vehicle_command_t()
        m.utime = int(time.time() * 1e6)
        m.seq = 100 + i
        m.throttle = 0.25 * (i % 4)
        m.steering = -0.5
        m.headlights = 2
        m.indicators = 3
        m.engaged = i % 2 == 0
        # The signature fields round-trip too (a string, an int64 and a fixed byte array).
        m.source, m.authority, m.counter = "interop", 1, 1764057600000000 + i
        m.mac = bytes(range(i, i + 16))
        sent_us.append(time.time_ns() // 1000)
        lc.publish("INTEROP_IN", m.encode())
        # Event order: the echo, or the peer's end. HANG_BACKSTOP_S only ends a hung run (a
        # lost datagram); a slow machine waits as long as it needs.
        backstop = time.monotonic() + HANG_BACKSTOP_S
        while len(got) <= i and proc.poll() is None and time.monotonic() < backstop:
            r, _, _ = select.select([lc.fileno()], [], [], 0.2)
            if r:
                lc.handle()
        assert len(got) == i + 1, f"no echo for message {i} (peer exit code {proc.poll()})"
        read_us.append(time.time_ns() // 1000)
        e = got[i]
        assert e.seq == m.seq + 1 and abs(e.throttle - m.throttle) < 1e-6 and e.steering == -0.5
        assert e.source == "interop" and e.counter == m.counter and e.mac == m.mac
        assert e.headlights == 2 and e.indicators == 3 and e.engaged == m.engaged
    assert proc.wait(timeout=HANG_BACKSTOP_S) == 0
    # The tap's own thread reads the same datagrams: wait until it has read every echo (event
    # order, not a sleep), the backstop again only against a hang.
    backstop = time.monotonic() + HANG_BACKSTOP_S
    while len(tapped) < count and time.monotonic() < backstop:
        time.sleep(0.01)
    tap.close()
    # The tap read the very bytes the lcm library decoded, each stamped between its request's
    # publication and the moment its echo had been read here.
    assert len(tapped) == count, f"the wire tap read {len(tapped)} of {count} echoes"
    for i, (data, us) in enumerate(tapped):
        assert vehicle_command_t.decode(data).seq == got[i].seq, f"tapped echo {i} differs"
        assert sent_us[i] <= us <= read_us[i], f"echo {i}: receive time {us} outside its round trip"
    # Packets by hand: a small message round-trips; a fragment ("LC03") or junk is not one.
    assert lcm_wire.parse_short(lcm_wire.packet("CH", b"xyz", 7)) == ("CH", b"xyz")
    assert lcm_wire.parse_short(b"LC03" + bytes(20)) is None
    assert lcm_wire.parse_short(b"LC0") is None
    try:
        lcm_wire.group_and_port("memq://")
        raise AssertionError("memq:// taken for a udpm URL")
    except ValueError as e:
        assert "memq://" in str(e)
    print(f"interop ok: {count} vehicle_command_t round trips Python(PyPI lcm) <-> C++(Debian LCM)")
