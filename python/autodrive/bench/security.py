"""tools/bench security: who can drive the car (issue "Hardening: only an authorised source can
drive a car"). The HIL parking demo runs (sim + unchanged runtime + autonomy, lockstep) while a
hostile publisher on the same bus, for the whole run, sends <VEH>_COMMAND
  - unsigned (full throttle 0.93 at full right lock, claiming source "autonomy" and a person's
    authority), by LCM multicast and by plain unicast UDP to the LCM port;
  - signed with a wrong key (throttle 0.87 at full left lock, source "teleop", a person's
    authority);
  - replays of the autonomy's own signed commands, byte for byte, 0.1 s later.
Figures:
  replayed_cmd_applied  commands the gate applied beyond those the signed sources had sent
      (applied_beyond_sent: a replay, or any foreign command, applied shows there)
  unsigned_cmd_applied, wrong_key_cmd_applied  <VEH>_STATE samples with that hostile
      command's throttle and lock applied by the Nano
  foreign_source_takeover  changes of control to any source but the autonomy
  demo_success_under_attack  the mission parked without a collision; the demo's report counts
      the foreign commands (foreign_commands) and so says success: false
  serial_cmd_hz_under_flood  COMMAND frames per second on the serial link (autodrive-runtime
      --only bridge, fake Nano on a pty) while 40000 commands a second go to <VEH>_COMMAND
      (1 in 8 valid, signed by the lease holder, the rest unsigned; lcm_flood_msgs_per_s is the
      rate the publisher reached), against the configured cap (bridge.command_rate_hz of the
      car's config: the bridge's token bucket)
The input-checking figures of security_inputs.py are merged in when that module exists.
Progress on stderr; the last line is one JSON object. Usage: tools/bench security [--help]"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import random
import select
import socket
import sys
import tempfile
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any


from autodrive.core import channels, command_auth, lcm_wire, lcmtypes
from autodrive.hil import demo
from autodrive.bench import Progress, build_dir, link, out_dir, print_figures
from autodrive.core import seeds
from autodrive.bench.goals import at_most, equals, judge

# Every goal, the demo's included: with --skip-demo its figures are missing and fail their goals.
GOALS = {
    "unsigned_cmd_applied": equals("unsigned_cmd_applied", 0),
    "replayed_cmd_applied": equals("replayed_cmd_applied", 0),
    "wrong_key_cmd_applied": equals("wrong_key_cmd_applied", 0),
    "foreign_source_takeover": equals("foreign_source_takeover", 0),
    "demo_success_under_attack": equals("demo_success_under_attack", True),
    # the demo parks, yet exits 1 because its bridge dropped foreign commands: an attack on the
    # bus is named to the user, never passed over as a clean run
    "demo_exit_names_the_attack": equals("demo_exit_code", 1),
    "serial_cmd_rate_under_flood": at_most("serial_cmd_rate_ratio", 1.1),
}

PORT_DEMO, PORT_FLOOD = 7848, 7849
VEHICLE = channels.vehicle_name(1)
HOSTILE_HZ = 50.0
UNSIGNED_THROTTLE, WRONG_KEY_THROTTLE = 0.93, 0.87
REPLAY_DELAY_S = 0.1
log = Progress("security")


def url(port: int) -> str:
    return f"udpm://239.255.76.67:{port}?ttl=0"


class Hostile:
    """The hostile publisher: a thread that keeps attacking until stop()."""

    def __init__(self, types: Any, lcm_url: str, port: int, victim: str = "autonomy") -> None:
        """victim: the legitimate source whose commands are recorded and replayed."""
        self.types, self.url, self.port, self.victim = types, lcm_url, port, victim
        self.channel = channels.channel("COMMAND", VEHICLE)
        self.sent = {"unsigned": 0, "unicast": 0, "bad_mac": 0, "replay": 0}
        self.controls: list[tuple[float, Any]] = []  # (monotonic [s], control_status_t)
        self.holders: set[str] = set()
        self.wrong = command_auth.Signer(
            os.urandom(command_auth.KEY_BYTES), VEHICLE, "teleop", command_auth.AUTHORITY_PERSON
        )
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._seen_control = threading.Event()

    def start(self) -> None:
        self._thread.start()

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()

    def _command(self, throttle: float, steering: float) -> Any:
        c = self.types.vehicle_command_t()
        c.utime = time.time_ns() // 1000
        c.throttle, c.steering, c.engaged = throttle, steering, True
        c.mac = bytes(command_auth.MAC_BYTES)  # lcm-gen's default ("") does not encode
        return c

    def _run(self) -> None:
        lc = lcmtypes.bus(self.url)
        udp = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        captured: list[tuple[float, bytes]] = []
        ch_control = channels.channel("CONTROL", VEHICLE)

        replayed: set[bytes] = set()  # each recorded command once (our replays come back too)

        def on_command(_ch: str, data: bytes) -> None:
            m = self.types.vehicle_command_t.decode(data)
            if (
                m.source == self.victim
                and any(m.mac)  # its own forged "autonomy" commands are not the victim's
                and data not in replayed
                and not self._stop.is_set()
            ):
                replayed.add(data)
                captured.append((time.monotonic() + REPLAY_DELAY_S, data))

        def on_control(_ch: str, data: bytes) -> None:
            m = self.types.control_status_t.decode(data)
            self.controls.append((time.monotonic(), m))
            if m.holder:
                self.holders.add(m.holder)
            self._seen_control.set()

        lc.subscribe(self.channel, on_command)
        lc.subscribe(ch_control, on_control)
        next_t = time.monotonic()
        seqno = 0
        while not self._stop.is_set():
            while select.select([lc.fileno()], [], [], max(0.0, next_t - time.monotonic()))[0]:
                lc.handle()
            now = time.monotonic()
            if now < next_t:
                continue
            next_t += 1.0 / HOSTILE_HZ
            if not self._seen_control.is_set():
                continue  # the bridge is not up yet: nothing would be counted
            unsigned = self._command(UNSIGNED_THROTTLE, -1.0)
            unsigned.source, unsigned.authority = "autonomy", command_auth.AUTHORITY_PERSON
            lc.publish(self.channel, unsigned.encode())
            self.sent["unsigned"] += 1
            seqno += 1
            udp.sendto(
                lcm_wire.packet(self.channel, unsigned.encode(), seqno), ("127.0.0.1", self.port)
            )
            self.sent["unicast"] += 1
            wrong = self.wrong.sign(self._command(WRONG_KEY_THROTTLE, 1.0))
            lc.publish(self.channel, wrong.encode())
            self.sent["bad_mac"] += 1
            while captured and captured[0][0] <= now:
                lc.publish(self.channel, captured.pop(0)[1])
                self.sent["replay"] += 1
        udp.close()


HOSTILE_RUN = 5  # consecutive STATE samples: a legitimate slew passes these values, never stays


def hostile_throttle_samples(
    log_path: Path,
    types: Any,
    hostile: tuple[tuple[float, float], ...] = (
        (UNSIGNED_THROTTLE, -1.0),
        (WRONG_KEY_THROTTLE, 1.0),
    ),
) -> int:
    """<VEH>_STATE samples in runs of HOSTILE_RUN or more with a hostile command applied by the
    Nano (its throttle and its full lock; hostile: the (throttle, steering) pairs looked for)."""
    ch = channels.channel("STATE", VEHICLE)
    n, run = 0, 0
    for ev in lcmtypes.events(log_path):
        if ev.channel == ch:
            m = types.vehicle_state_t.decode(ev.data)
            match = any(
                abs(m.throttle_applied - t) < 0.005 and abs(m.steering_applied - st) < 0.02
                for t, st in hostile
            )
            run = run + 1 if match else 0
            n += run if run == HOSTILE_RUN else (1 if run > HOSTILE_RUN else 0)
    return n


Command = tuple[int, str, int]  # (counter: the sender's wall clock [us], source, seq)


def applied_beyond_sent(commands: list[Command], statuses: list[tuple[int, int]]) -> int:
    """Commands the gate applied beyond those its signed sources had sent: the most over the
    run. commands: every validly signed <VEH>_COMMAND on the recorded bus, originals and
    byte-for-byte replays alike; statuses: (log time [us, wall clock], applied) of each
    <VEH>_CONTROL. The sources and the logger share the machine's wall clock.

    Each source numbers its messages (seq, one per message) and stamps them with its wall clock
    (counter), both covered by the signature, and the gate applies a counter at most once. So
    at a status logged at t the gate can have applied at most the commands sent before t: for
    each source, fewer than the seq of its first command sent after t (the logged command with
    the smallest counter above t, whether the logger kept the original or only a replay). A
    command applied twice (a replay), or one without a valid signature, makes applied exceed
    that. Why not compare the gate's drop counters with the commands logged some fixed time
    before (the old way, which reported 20 unexplained replays): under load the bridge reads
    the bus 1-4 s behind the logger, and both the logger and the bridge lose packets (a run
    here: the logger kept 1713 of 2829 bad-signature commands and lost 35 of the autonomy's
    1276 commands, 25 in a row, original and replay). This bound depends on neither."""
    first: dict[str, tuple[int, int]] = {}  # source -> (counter, seq) of its first command
    for counter, src, seq in commands:
        first[src] = min(first.get(src, (counter, seq)), (counter, seq))
    by_counter = sorted(commands)
    worst = 0
    for t, applied in statuses:
        sent = 0
        for src, (c0, s0) in first.items():
            if c0 > t:
                continue  # not started yet
            after = next((seq for c, s, seq in by_counter if c > t and s == src), None)
            if after is None:
                sent = -1  # no command of it after the status was logged: no bound
                break
            sent += after - s0
        if sent >= 0:
            worst = max(worst, applied - sent)
    return worst


def log_applied_beyond_sent(log_path: Path, types: Any, key: bytes) -> int:
    """applied_beyond_sent over the recorded bus: the validly signed <VEH>_COMMANDs (checked
    with the car's key) and the applied count of every <VEH>_CONTROL."""
    ch_cmd, ch_control = (channels.channel(c, VEHICLE) for c in ("COMMAND", "CONTROL"))
    commands: list[Command] = []
    statuses: list[tuple[int, int]] = []
    for ev in lcmtypes.events(log_path):
        if ev.channel == ch_cmd:
            m = types.vehicle_command_t.decode(ev.data)
            if m.source and m.authority and any(m.mac):
                if command_auth.mac_of(key, command_auth.canonical_bytes(m, VEHICLE)) == m.mac:
                    commands.append((m.counter, m.source, m.seq))
        elif ev.channel == ch_control:
            statuses.append((ev.timestamp, types.control_status_t.decode(ev.data).applied))
    return applied_beyond_sent(commands, statuses)


def demo_under_attack(build: Path, out: Path, timeout_s: float, key: bytes) -> dict[str, Any]:
    types = lcmtypes.load(build)
    hostile = Hostile(types, url(PORT_DEMO), PORT_DEMO)
    hostile.start()
    log(f"the parking demo with a hostile publisher on {url(PORT_DEMO)} ...")
    args = demo.parse_args(
        ["--build", str(build), "--out", str(out), "--headless", "--lcm-url", url(PORT_DEMO)]
        + ["--timeout", f"{timeout_s:g}"]
    )
    try:
        code = demo.run(args, console=sys.stderr)
    finally:
        hostile.stop()
    rep = json.loads((out / "report.json").read_text())
    beyond = log_applied_beyond_sent(out / "run.lcmlog", types, key)
    state_hits = hostile_throttle_samples(out / "run.lcmlog", types)
    # the bad-signature commands are the clock of the accounting: their own figure is what the
    # Nano applied of them
    wrong_key_hits = hostile_throttle_samples(
        out / "run.lcmlog", types, ((WRONG_KEY_THROTTLE, 1.0),)
    )
    takeovers = sorted(h for h in hostile.holders if h != "autonomy")
    return {
        "unsigned_cmd_applied": state_hits - wrong_key_hits,
        "replayed_cmd_applied": beyond,
        "wrong_key_cmd_applied": wrong_key_hits,
        "foreign_source_takeover": len(takeovers),
        "foreign_holders": takeovers,
        "demo_success_under_attack": bool(rep.get("mission_success"))
        and rep.get("collisions") == 0,
        "demo_report_success": rep.get("success"),
        "demo_exit_code": code,
        "foreign_commands": rep.get("foreign_commands"),
        "hostile_sent": dict(hostile.sent),
        "hostile_state_samples": state_hits,
        "final_pos_error_m": rep.get("final_pos_error_m"),
        "path_length_m": rep.get("path_length_m"),
        "min_clearance_m": rep.get("min_clearance_m"),
    }


def flood(build: Path, work: Path) -> dict[str, Any]:
    return link.flood(build, work, PORT_FLOOD, log)


def input_figures() -> dict[str, Any]:
    """The input-checking half (security_inputs.py), when it exists."""
    try:
        mod = importlib.import_module("autodrive.bench.security_inputs")
    except ModuleNotFoundError:
        log("security_inputs.py does not exist here: the input-checking figures are not measured")
        return {"security_inputs": "not present"}
    run: Callable[[Callable[[str], None]], dict[str, Any]] = getattr(mod, "run")
    return run(log)


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(
        prog="tools/bench security",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--timeout", type=float, default=240.0, help="demo timeout [s] (default 240)")
    p.add_argument(
        "--skip-demo",
        action="store_true",
        help="only the flood figure (goals_met is then false: the demo's figures are missing)",
    )
    a = p.parse_args(argv)
    build = build_dir("security")
    needed = ("autodrive-runtime", "runtime-link-bench") + (() if a.skip_demo else demo.PROGRAMS)
    for prog in needed:
        if not os.access(build / "bin" / prog, os.X_OK):
            log(f"ERROR: {build / 'bin' / prog} missing (build it first)")
            return 1
    figures: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="adr-bench-security.") as work:
        # A fresh key for this run (the user's own keys are not touched).
        os.environ["AUTODRIVE_KEY_DIR"] = str(Path(work) / "keys")
        command_auth.create_key(command_auth.default_key_path(VEHICLE))
        if not a.skip_demo:
            key = command_auth.load_key(command_auth.default_key_path(VEHICLE))
            figures.update(demo_under_attack(build, out_dir() / "security", a.timeout, key))
        figures.update(flood(build, Path(work)))
    figures.update(input_figures())
    span = seeds.span(seeds.DEVELOPMENT_MISSION_SEED, 1)  # the demo's default seed
    print_figures(judge(figures, GOALS, span), key_value_lines=True)
    return 0
