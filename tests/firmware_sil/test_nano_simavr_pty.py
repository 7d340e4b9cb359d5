"""nano-simavr end to end over a real pty: the real ELF says HELLO and streams STATE frames,
accepts COMMAND frames written to the pty, and logs the resulting motor PWM change.
Timeouts below are liveness bounds only (the machine is shared); nothing asserts on wall time."""
import os
import struct
import subprocess
import tempfile
import termios
import time
import tty
from typing import Callable

SYNC = b"\xa5\x5a"
ID_COMMAND, ID_HELLO, ID_STATE = 0x01, 0x81, 0x82


def crc16(data: bytes) -> int:
    crc = 0xFFFF
    for b in data:
        crc ^= b << 8
        for _ in range(8):
            crc = ((crc << 1) ^ 0x1021) & 0xFFFF if crc & 0x8000 else (crc << 1) & 0xFFFF
    return crc


def frame(fid: int, seq: int, payload: bytes) -> bytes:
    body = bytes([len(payload), fid, seq & 0xFF]) + payload
    return SYNC + body + struct.pack("<H", crc16(body))


def parse(buf: bytearray):
    """Yields (id, payload) of every good frame in buf; consumes what it used."""
    out = []
    while True:
        i = buf.find(SYNC)
        if i < 0:
            del buf[: max(0, len(buf) - 1)]
            return out
        del buf[:i]
        if len(buf) < 7 or len(buf) < 7 + buf[2]:
            return out
        n = buf[2]
        body = bytes(buf[2 : 5 + n])
        (crc,) = struct.unpack("<H", buf[5 + n : 7 + n])
        if crc == crc16(body):
            out.append((buf[3], bytes(buf[5 : 5 + n])))
            del buf[: 7 + n]
        else:
            del buf[:1]


def test_nano_simavr_on_a_pty(program: Callable[[str], str], nano_elf: str) -> None:
    exe, elf = program("nano-simavr"), nano_elf
    with tempfile.TemporaryDirectory() as tmp:
        link, log = os.path.join(tmp, "nano"), os.path.join(tmp, "pwm.log")
        proc = subprocess.Popen(
            [exe, "--elf", elf, "--pty", link, "--pwm-log", log, "--encoder-hz", "1000"]
        )
        try:
            deadline = time.monotonic() + 60
            while not os.path.islink(link):
                assert proc.poll() is None, "nano-simavr exited early"
                assert time.monotonic() < deadline, "no pty symlink"
                time.sleep(0.05)
            fd = os.open(link, os.O_RDWR | os.O_NOCTTY)
            tty.setraw(fd)
            termios.tcflush(fd, termios.TCIOFLUSH)
            buf, frames = bytearray(), []
            seq, state = 0, None

            def pump(until, cmd=None, limit_s=60.0):
                """Streams cmd every 10 ms and reads frames until until() or the liveness
                limit (the simulation may run slower than real time on a loaded machine)."""
                nonlocal seq
                end = time.monotonic() + limit_s
                while not until():
                    assert time.monotonic() < end, "nano-simavr stopped answering"
                    assert proc.poll() is None, "nano-simavr exited"
                    if cmd is not None:
                        os.write(fd, frame(ID_COMMAND, seq, struct.pack("<HhhBBB", seq, *cmd)))
                        seq += 1
                    time.sleep(0.01)
                    try:
                        buf.extend(os.read(fd, 4096))
                    except BlockingIOError:
                        pass
                    frames.extend(parse(buf))

            def states():
                return [p for i, p in frames if i == ID_STATE]

            def mode():  # u8 mode after u16 battery_mv and u8 lights
                return states()[-1][49] if states() else None

            os.set_blocking(fd, False)
            os.write(fd, frame(0x03, 0, b""))  # HELLO_REQUEST
            pump(lambda: any(i == ID_HELLO for i, _ in frames) and len(states()) >= 10)
            # arm (engaged=0 then engaged=1) and drive at half throttle
            n0 = len(states())
            pump(lambda: len(states()) >= n0 + 5, (0, 0, 0, 0, 0))
            pump(
                lambda: mode() == 1 and struct.unpack_from("<h", states()[-1], 16)[0] >= 500,
                (500, 0, 0, 0, 1),
            )
            enc_left = struct.unpack_from("<i", states()[-1], 4)[0]
            assert enc_left > 0, "encoder edges from --encoder-hz not counted"
            os.close(fd)
        finally:
            proc.terminate()
            proc.wait(timeout=30)
        duties = [int(l.split()[3]) for l in open(log) if not l.startswith("#")]
        assert max(duties) > 100, f"no motor PWM in the log (max duty {max(duties)})"
    print("nano-simavr pty test passed")
