#!/usr/bin/env python3
"""Flashing through the real bootloader: nano-simavr starts as a Nano being flashed (application
flash erased, Debian's Optiboot at 0x7E00, reset into it once the uploader talks), PlatformIO
uploads the firmware it built (`pio run -e nano_offline_new -t upload --upload-port <pty>`:
avrdude -c arduino at 115200 over the pty, Optiboot writes the flash with SPM), Optiboot's
watchdog reset starts the application, and the flashed firmware answers the handshake: HELLO
with protocol version 1 and the build id PlatformIO stamped (the git short hash), then STATE.
usage: test_optiboot_upload.py <repo root> <nano-simavr> <elf> <work dir>
Timeouts are liveness bounds only; nothing asserts on wall time."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
import termios
import time
import tty
from pathlib import Path

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from test_nano_simavr_pty import ID_HELLO, ID_STATE, frame, parse  # noqa: E402
from test_pio_build import pio_env  # noqa: E402

OPTIBOOT = Path(
    "/usr/share/arduino/hardware/arduino/avr/bootloaders/optiboot/optiboot_atmega328.hex"
)


def main() -> int:
    root, exe, elf, work = (Path(a).resolve() for a in sys.argv[1:5])
    assert OPTIBOOT.is_file(), f"{OPTIBOOT} missing (Debian package arduino-core-avr)"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    sys.path.insert(0, str(root / "python"))
    from autodrive_tools.pio_offline import ensure_tool_scons

    ensure_tool_scons(work / "core")
    link = work / "nano"
    sim_log = open(work / "nano-simavr.log", "w")
    proc = subprocess.Popen(
        [str(exe), "--elf", str(elf), "--bootloader", str(OPTIBOOT), "--pty", str(link)],
        stdout=sim_log,
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 60
        while not link.is_symlink():
            assert proc.poll() is None, "nano-simavr exited early"
            assert time.monotonic() < deadline, "no pty symlink"
            time.sleep(0.05)
        up = subprocess.run(
            [
                str(root / ".venv/bin/pio"),
                "run",
                "-d",
                str(root),
                "-e",
                "nano_offline_new",
                "-t",
                "upload",
                "--upload-port",
                str(link),
            ],
            env=pio_env(work),
            capture_output=True,
            text=True,
            timeout=900,
        )
        out = up.stdout + up.stderr
        (work / "upload.log").write_text(out)
        assert up.returncode == 0, f"upload failed:\n{out[-4000:]}"
        assert "bytes of flash verified" in out, f"avrdude did not verify:\n{out[-4000:]}"
        print(next(line for line in out.splitlines() if "bytes of flash verified" in line))

        fd = os.open(link, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(fd)
        termios.tcflush(fd, termios.TCIOFLUSH)
        os.set_blocking(fd, False)
        buf, frames = bytearray(), []
        end = time.monotonic() + 120
        hello = None
        while hello is None or sum(1 for i, _ in frames if i == ID_STATE) < 10:
            assert time.monotonic() < end, "the flashed firmware did not answer"
            assert proc.poll() is None, "nano-simavr exited"
            if hello is None:
                os.write(fd, frame(0x03, 0, b""))  # HELLO_REQUEST
            time.sleep(0.05)
            try:
                buf.extend(os.read(fd, 4096))
            except BlockingIOError:
                pass
            frames.extend(parse(buf))
            hello = next((p for i, p in frames if i == ID_HELLO), None)
        os.close(fd)
        fw = struct.unpack_from("<BBBBII", hello)
        want_id = int(
            subprocess.run(
                ["git", "-C", str(root), "rev-parse", "--short=8", "HEAD"],
                capture_output=True,
                text=True,
                check=True,
            ).stdout.strip(),
            16,
        )
        print(
            f"HELLO fw {fw[0]}.{fw[1]}.{fw[2]} proto {fw[3]} schema 0x{fw[4]:08x} build 0x{fw[5]:08x}"
        )
        assert fw[3] == 1, f"protocol version {fw[3]}"
        assert fw[5] == want_id, f"build id 0x{fw[5]:08x}, PlatformIO stamped 0x{want_id:08x}"
    finally:
        proc.terminate()
        proc.wait(timeout=30)
        sim_log.close()
    print("Optiboot upload into simavr: flashed firmware answers the handshake")
    return 0


if __name__ == "__main__":
    sys.exit(main())
