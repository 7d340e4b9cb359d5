"""PlatformIO builds the firmware here, offline (a plain `pio run`: default_envs is nano_offline,
the platform in firmware/nano/pio, Debian's avr-gcc and Arduino core, SCons from PyPI as tool-scons), and its
ELF matches the CMake AVR build's: the same .text, .data and .bss sizes and the same symbols
with the same sizes (only where LTO places a few functions may differ; see firmware/nano/README).
Then the upload command line: `pio run -e nano_offline[_new] -t upload --upload-port <pty>`
must run avrdude with the Nano bootloader's settings and talk STK500 on that port (the test
holds the pty's other end and sees avrdude's GET_SYNC), without a board.
Last, the whole flashing path without a board: `pio run -e nano_offline -t upload` into
nano-simavr started as a Nano being flashed (its application flash erased, Debian's ATmegaBOOT
bootloader running on a pty); avrdude writes and verifies the image, the bootloader starts it,
and the flashed firmware must then announce itself with a HELLO frame and stream STATE frames.
PlatformIO's core and build dirs are private to the test (nothing in ~/.platformio or .pio).
"""

from __future__ import annotations

import os
import pty
import re
import select
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path
from typing import Callable

import pytest

STK_GET_SYNC = b"\x30\x20"  # STK500v1 Cmnd_STK_GET_SYNC, Sync_CRC_EOP
# Frame start of the Nano link and the HELLO / STATE ids (firmware/nano/core/protocol/PROTOCOL.md).
FRAME_SYNC = b"\xa5\x5a"
PROTOCOL_ID_HELLO, PROTOCOL_ID_STATE = 0x81, 0x82


def sections(elf: Path) -> dict[str, int]:
    out = subprocess.run(["avr-size", "-A", str(elf)], check=True, capture_output=True, text=True)
    sizes: dict[str, int] = {}
    for line in out.stdout.splitlines():
        parts = line.split()
        if len(parts) >= 2 and parts[0] in (".text", ".data", ".bss") and parts[1].isdigit():
            sizes[parts[0]] = int(parts[1])
    return sizes


def symbols(elf: Path) -> list[tuple[str, str, int]]:
    out = subprocess.run(
        ["avr-nm", "-S", str(elf)], check=True, capture_output=True, text=True
    ).stdout
    syms = []
    for line in out.splitlines():
        parts = line.split()
        if len(parts) == 4:  # address size type name: only symbols with a size
            syms.append((parts[3], parts[2], int(parts[1], 16)))
    return sorted(syms)


def pio_env(work: Path) -> dict[str, str]:
    env = dict(os.environ)
    env["PLATFORMIO_CORE_DIR"] = str(work / "core")
    env["PLATFORMIO_BUILD_DIR"] = str(work / "build")
    env["PLATFORMIO_SETTING_ENABLE_TELEMETRY"] = "no"
    env["PLATFORMIO_SETTING_CHECK_PLATFORMIO_INTERVAL"] = "3650"
    return env


def check_build(root: Path, cmake_elf: Path, work: Path, pio: Path) -> Path:
    # A plain `pio run`, no -e: the reflex of every PlatformIO user builds the offline env
    # (default_envs) and nothing else.
    r = subprocess.run(
        [str(pio), "run", "-d", str(root)],
        env=pio_env(work),
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert r.returncode == 0, f"pio run failed:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    assert "HTTPClientError" not in r.stdout + r.stderr, "PlatformIO tried its registry"
    built = sorted(p.name for p in (work / "build").iterdir() if p.is_dir())
    assert built == ["nano_offline"], f"a plain pio run built {built}, not only nano_offline"
    pio_elf = work / "build" / "nano_offline" / "firmware.elf"
    assert pio_elf.is_file(), f"no {pio_elf}"
    assert (work / "build" / "nano_offline" / "firmware.hex").is_file(), "no firmware.hex"
    a, b = sections(cmake_elf), sections(pio_elf)
    print(f"CMake {cmake_elf}: {a}\nPlatformIO {pio_elf}: {b}")
    assert set(a) == {".text", ".data", ".bss"}, f"sections of {cmake_elf}: {a}"
    assert a == b, f"section sizes differ: CMake {a}, PlatformIO {b}"
    sa, sb = symbols(cmake_elf), symbols(pio_elf)
    assert sa == sb, "symbols differ: " + str(sorted(set(sa) ^ set(sb))[:20])
    print(f"{len(sa)} sized symbols, the same names, types and sizes")
    return pio_elf


def check_upload(root: Path, work: Path, pio: Path, env_name: str, baud: int) -> None:
    """Runs the upload against a pty we hold; stops it once avrdude has sent GET_SYNC."""
    master, slave = pty.openpty()
    port = os.ttyname(slave)
    proc = subprocess.Popen(
        [
            str(pio),
            "run",
            "-d",
            str(root),
            "-e",
            env_name,
            "-t",
            "upload",
            "--upload-port",
            port,
            "-v",
        ],
        env=pio_env(work),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,  # avrdude runs under a shell: stop the whole group at the end
    )
    assert proc.stdout is not None
    os.set_blocking(proc.stdout.fileno(), False)
    out = b""
    seen = b""
    deadline = time.monotonic() + 300
    try:
        while time.monotonic() < deadline and STK_GET_SYNC not in seen:
            ready, _, _ = select.select([master, proc.stdout], [], [], 0.5)
            if master in ready:
                seen += os.read(master, 256)
            if proc.stdout in ready:
                out += proc.stdout.read() or b""
            if proc.poll() is not None and master not in ready:
                break
    finally:
        os.killpg(proc.pid, signal.SIGKILL)
        rest = proc.communicate()[0] or b""
        out += rest
        os.close(master)
        os.close(slave)
    text = out.decode(errors="replace")
    m = re.search(r"^avrdude .*$", text, re.MULTILINE)
    assert m, f"{env_name}: no avrdude command in PlatformIO's output:\n{text[-3000:]}"
    cmd = m.group(0)
    print(f"{env_name}: {cmd}")
    m_hex = re.search(r" -U flash:w:(\S+):i$", cmd)
    assert m_hex, f"{env_name}: no flash:w:<hex>:i in {cmd}"
    hex_path = (root / m_hex.group(1)).resolve()  # PlatformIO names it relative to the project
    want_hex = (work / "build" / env_name / "firmware.hex").resolve()
    assert hex_path == want_hex, f"{env_name}: uploads {hex_path}, built {want_hex}"
    want = f'avrdude -p atmega328p -c arduino -P "{port}" -b {baud} -D -U flash:w:'
    assert cmd.startswith(want), f"{env_name}: avrdude command\n  got  {cmd}\n  want {want}..."
    assert STK_GET_SYNC in seen, f"{env_name}: avrdude sent no STK500 GET_SYNC on {port}: {seen!r}"
    print(f"{env_name}: avrdude sent GET_SYNC on {port} at {baud} baud")


def frame_ids(data: bytes) -> list[int]:
    """The id byte of every frame start in a byte stream (sync, length, id, ...)."""
    ids = []
    at = data.find(FRAME_SYNC)
    while at >= 0 and at + 3 < len(data):
        ids.append(data[at + 3])
        at = data.find(FRAME_SYNC, at + 2)
    return ids


def upload_once(root: Path, work: Path, pio: Path, simavr: Path, bootloader: Path) -> str:
    """One upload into a freshly started nano-simavr; returns what went wrong, or ''."""
    port = work / "simavr-nano"
    sim = subprocess.Popen(
        [str(simavr), "--bootloader", str(bootloader), "--pty", str(port)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    try:
        deadline = time.monotonic() + 30
        while not port.exists() and time.monotonic() < deadline and sim.poll() is None:
            time.sleep(0.05)
        if not port.exists():
            return f"nano-simavr made no pty at {port}"
        up = subprocess.run(
            [str(pio), "run", "-d", str(root), "-e", "nano_offline", "-t", "upload"]
            + ["--upload-port", str(port)],
            env=pio_env(work),
            capture_output=True,
            text=True,
            timeout=240,
        )
        out = up.stdout + up.stderr
        m = re.search(r"(\d+) bytes of flash verified", out)
        if up.returncode != 0 or not m:
            return f"the upload failed (rc {up.returncode}):\n{out[-2000:]}"
        print(f"nano_offline into simavr: {m.group(0)}")
        fd = os.open(str(port), os.O_RDWR | os.O_NOCTTY | os.O_NONBLOCK)
        try:
            got = b""
            deadline = time.monotonic() + 20
            while time.monotonic() < deadline:
                ids = frame_ids(got)
                if PROTOCOL_ID_HELLO in ids and ids.count(PROTOCOL_ID_STATE) >= 10:
                    print(
                        f"the flashed firmware runs: HELLO and {ids.count(PROTOCOL_ID_STATE)} STATE frames"
                    )
                    return ""
                ready, _, _ = select.select([fd], [], [], 0.2)
                if ready:
                    got += os.read(fd, 4096)
        finally:
            os.close(fd)
        return f"no HELLO and STATE frames after the upload: ids {frame_ids(got)[:20]}"
    finally:
        sim.terminate()
        try:
            sim.wait(timeout=10)
        except subprocess.TimeoutExpired:
            sim.kill()


def check_upload_into_simavr(
    root: Path, work: Path, pio: Path, simavr: Path, bootloader: Path
) -> None:
    # The one retry left in the suite, and why (issue 34): the cause is a third-party tool's own
    # timeout. avrdude 7.1's arduino programmer waits for each STK500 answer on wall time
    # ("programmer is not responding"; it has no option to lengthen the wait), and the
    # simulated optiboot answers at simavr's pace, slower than real time on a starved machine.
    # A try that fails prints why; 3 failed tries fail the test.
    errors = []
    for attempt in range(3):
        why = upload_once(root, work, pio, simavr, bootloader)
        if not why:
            return
        print(f"upload attempt {attempt + 1}: {why}")
        errors.append(why)
    raise AssertionError("upload through the bootloader in simavr failed 3 times:\n" + errors[-1])


def test_pio_build_matches_cmake_and_uploads(
    root: Path, program: Callable[[str], str], nano_elf: str, pytestconfig: pytest.Config
) -> None:
    work, bootloader = (
        Path(pytestconfig.getoption(o)).resolve() for o in ("pio_work_dir", "bootloader_hex")
    )
    root, cmake_elf, simavr = (
        root.resolve(),
        Path(nano_elf).resolve(),
        Path(program("nano-simavr")).resolve(),
    )
    pio = root / ".venv" / "bin" / "pio"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    sys.path.insert(0, str(root / "python"))
    from autodrive.devtools.pio_offline import ensure_tool_scons

    ensure_tool_scons(work / "core")
    check_build(root, cmake_elf, work, pio)
    check_upload(root, work, pio, "nano_offline", 57600)
    check_upload(root, work, pio, "nano_offline_new", 115200)
    check_upload_into_simavr(root, work, pio, simavr, bootloader)
    print("PlatformIO offline build and upload command ok")
