"""A gamepad drives the ego car from the window, as a person does it (issue 36):
autodrive-sim --view --gamepad PATH in its own Xvfb with its ptys, the unchanged
autodrive-runtime's bridge on the Nano pty, real LCM. This machine has no /dev/input: PATH is a
FIFO (mkfifo) into which the test writes the kernel's own joystick records, struct js_event
(linux/joystick.h: u32 time [ms], s16 value, u8 type, u8 number), the bytes autodrive-teleop
reads from /dev/input/js0. xdotool clicks the Car section's Driving/Manual radio; the test holds
the dead-man button and pushes the throttle stick. Checks: the car drives forward (ground
truth), the commands are the person's (source teleop, authority person) and the lease and the
HUD name teleop, the HUD says a gamepad is in use; releasing the dead-man stops the car (a
disengaged command follows the release, then the car stands); the pad unplugged while driving
(the FIFO's writer closed: its end, as a device's read fails once unplugged) stops the car, the
window says so and runs on, and Esc quits cleanly. Judged on sim time, ground truth and event
order; the waits are guards that fail with what was seen."""

from __future__ import annotations

import os
import struct
from collections.abc import Iterator
from pathlib import Path

import pytest

from window_rig import (
    AUTHORITY_PERSON,
    DRIVE_M,
    GUARD_S,
    MANUAL_RADIO,
    NEEDS_X_TOOLS,
    BridgeRig,
)

JS_EVENT_BUTTON, JS_EVENT_AXIS = 0x01, 0x02  # linux/joystick.h
DEADMAN_BUTTON = 4  # autodrive-teleop's default (LB)
THROTTLE_AXIS = 1  # left stick Y, up is negative
STICK_UP = -32767
STOPPED_M_S = 0.01  # [m/s]

pytestmark = NEEDS_X_TOOLS


class Pad:
    """The FIFO standing in for /dev/input/js0. Held open read-write: it has a writer before
    teleop opens it (a FIFO without one reads as its end, a pad unplugged)."""

    def __init__(self, path: Path) -> None:
        os.mkfifo(path)
        self.path = path
        self.fd = os.open(path, os.O_RDWR | os.O_NONBLOCK)
        self.ms = 0

    def event(self, kind: int, number: int, value: int) -> None:
        self.ms += 20
        os.write(self.fd, struct.pack("<IhBB", self.ms, value, kind, number))

    def unplug(self) -> None:
        if self.fd >= 0:
            os.close(self.fd)
        self.fd = -1


@pytest.fixture
def pad(tmp_path: Path) -> Iterator[Pad]:
    p = Pad(tmp_path / "js0")
    try:
        yield p
    finally:
        p.unplug()


@pytest.fixture
def rig(build_dir: Path, tmp_path: Path, lcm_url: str, pad: Pad) -> Iterator[BridgeRig]:
    r = BridgeRig(
        build_dir, tmp_path, lcm_url, display_offset=11, extra=["--gamepad", str(pad.path)]
    )
    try:
        yield r
    finally:
        r.close()


def drive(r: BridgeRig, pad: Pad) -> int:
    """Holds the dead-man, pushes the stick up, and waits for the car to drive DRIVE_M.
    Returns the number of commands seen before."""
    n = len(r.commands)
    ahead = r.ahead_of_here()
    pad.event(JS_EVENT_BUTTON, DEADMAN_BUTTON, 1)
    pad.event(JS_EVENT_AXIS, THROTTLE_AXIS, STICK_UP)
    r.until(lambda: "ok" if ahead() > DRIVE_M else None, f"the car to drive {DRIVE_M} m forward")
    print(f"the pad drove the car {ahead():.2f} m forward by t = {r.sim_time():.2f} s")
    return n


def stops(r: BridgeRig, n: int, why: str) -> None:
    """After command n: a disengaged command of teleop's, then the car standing."""
    r.until(lambda: "ok" if any(c[0] == "teleop" and not c[2] for c in r.commands[n:]) else None,
             f"a disengaged command ({why})")  # fmt: skip
    r.until(lambda: "ok" if abs(r.truth[-1][4]) < STOPPED_M_S else None, f"the car to stop ({why})")


def test_a_gamepad_drives_from_the_window(rig: BridgeRig, pad: Pad) -> None:
    r = rig
    r.until(lambda: "ok" if r.holder else None, "the bridge's NIGEL1_CONTROL")
    r.run_sim(0.3)
    r.click(*MANUAL_RADIO)
    started = r.until(lambda: next((s for s in r.lines if s.startswith("manual driving:")), None),
                       "manual mode to start autodrive-teleop")  # fmt: skip
    assert f"gamepad {pad.path}" in started, started
    n = drive(r, pad)
    engaged = [c for c in r.commands[n:] if c[2]]
    assert engaged and all(c[0] == "teleop" and c[1] == AUTHORITY_PERSON for c in engaged)
    assert max(c[3] for c in engaged) > 0, "no forward throttle commanded"
    r.until(lambda: "ok" if r.holder[-1] == "teleop" else None, "the lease to go to teleop")
    n_hud = len(r.hud())
    r.until(lambda: "ok" if any(kv.get("  control lease") == "teleop (person)"
                                 and "gamepad" in kv.get("driving", "")
                                 for _, kv in r.hud()[n_hud:]) else None,
             "a HUD frame naming teleop's lease and the gamepad")  # fmt: skip
    r.shot("window-gamepad")
    # the dead-man released: teleop disengages, the car stops
    n = len(r.commands)
    pad.event(JS_EVENT_BUTTON, DEADMAN_BUTTON, 0)
    stops(r, n, "dead-man released")
    # driving again, then the pad unplugged: teleop stops the car, the window says so
    drive(r, pad)
    n = len(r.commands)  # all engaged so far: the dead-man is held
    pad.unplug()
    r.until(lambda: next((s for s in r.lines if "gamepad" in s and "lost" in s), None),
             "the window to report the pad lost")  # fmt: skip
    stops(r, n, "gamepad lost")
    n_hud = len(r.hud())
    r.until(lambda: "ok" if any("lost" in kv.get("driving", "") for _, kv in r.hud()[n_hud:])
             else None, "a HUD frame saying the pad is lost")  # fmt: skip
    t = r.run_sim(0.5)  # the window runs on
    print(f"the window ran on to t = {t:.2f} s after the pad was lost")
    r.xdotool("key", "--window", r.wid, "Escape")
    assert r.sim is not None and r.sim.wait(timeout=GUARD_S) == 0
