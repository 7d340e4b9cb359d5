"""LCM wire interop: PyPI lcm (Python bindings) <-> Debian LCM 1.3.1 (C++), over real UDP
multicast on loopback. Run by ctest with PYTHONPATH at the generated Python bindings."""
import os
import select
import subprocess
import sys
import time

import lcm
from autodrive import vehicle_command_t

peer, port = sys.argv[1], int(sys.argv[2])
url = f"udpm://239.255.76.67:{port}?ttl=0"
count = 20
proc = subprocess.Popen(
    [peer, url, "INTEROP_IN", "INTEROP_OUT", str(count)], stdout=subprocess.PIPE, text=True
)
assert proc.stdout.readline().strip() == "ready", "C++ peer did not start"

lc = lcm.LCM(url)
got = []
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
    lc.publish("INTEROP_IN", m.encode())
    deadline = time.time() + 5.0
    while len(got) <= i and time.time() < deadline:
        r, _, _ = select.select([lc.fileno()], [], [], 0.2)
        if r:
            lc.handle()
    assert len(got) == i + 1, f"no echo for message {i} within 5 s"
    e = got[i]
    assert e.seq == m.seq + 1 and abs(e.throttle - m.throttle) < 1e-6 and e.steering == -0.5
    assert e.source == "interop" and e.counter == m.counter and e.mac == m.mac
    assert e.headlights == 2 and e.indicators == 3 and e.engaged == m.engaged
assert proc.wait(timeout=10) == 0
print(f"interop ok: {count} vehicle_command_t round trips Python(PyPI lcm) <-> C++(Debian LCM)")
