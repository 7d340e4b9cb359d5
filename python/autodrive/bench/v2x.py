"""tools/bench v2x: signed V2X under attack (issue "V2X you can trust"). Its own testbed CA in a
temp folder; the real simulator (autodrive-sim, Intersection School, real time, real UDP LCM)
is the receiver of the light attacks; the real SCM (HTTPS) that of the login brute force; the
C library of every receiver (libautodrive_v2x_auth.so) that of the crypto figures.
Figures (goal in brackets):
  forged_light_state_changes   light changes caused by unsigned, altered and wrong-role (a
      car's certificate) TRAFFIC_LIGHT_COMMANDs, 10 Hz for 3 s each [0]
  replayed_v2v_accepted        a 16-car V2V stream (20 Hz, 2 s) replayed 1 s later into the
      verifier that took the original [0]
  replayed_light_cmd_accepted  a signed light command replayed byte for byte 1 s later [0]
  revoked_accepted_after_1s    light changes by a revoked scm certificate's commands sent more
      than 1 s after tools/keys revoke [0]
  brute_force_accepted         sessions won by 1,000 login guesses (the right one among them)
      from their own address [0]
  brute_force_user_latency_ratio  median GET /api/state time of two logged-in users during the
      brute force over the quiet median, same run [<= 2]
  verify_us_p50, verify_us_p99, sign_us_p50   one V2V message, the C library [reported]
  bus16_cpu_share              CPU share of one core to check a 16-car bus at 20 Hz (300 msg/s
      from the 15 others) [reported; <= 0.05]
  forged_green_red_violations  red-light violations of a real smart-city run (3 cars, the
      real SCM, 30 s of sim time, the real Eye in lockstep: CITY_EYE) while forged GREEN
      advisories go to every car at 50 Hz [0]
  city_real_eye, city_eye_sync_give_ups  the three smart-city runs' poses came from the real
      Eye (their reports' pose_source "eye") [true], and the simulator never gave it up (a run
      that then depended on wall time) [0]
  ghost_car_extra_stop_s       the same run's held time charged to ghost cars: ghosts 0.3 m
      ahead of each car on V2V (unsigned; a real car's name signed by another car's certificate;
      real and unknown names with another authority's certificates; real cars' states replayed
      1 s of sim time later), and each city driver's own per-peer account (for every V2V peer
      it accepted, by name and certificate serial: the car time it held or slowed the car; any
      peer that is not a real car under its own certificate is a ghost), summed [0 s]
  ghost_in_peer_table_s        the same accounts' time any ghost was in any car's peer table
      [0 s]. (city_stop_difference_s_info, the stopped time of all cars over the longer of two
      quiet runs of the seed, is no ghost figure: two quiet runs differ by seconds on their own)
  eye_walk_ekf_drift_m         the same run's EKF error (POSE_MAP against GROUND_TRUTH, median
      over the last 10 s of sim time, the worst car) over the quiet runs', while forged Eye poses
      walk each car away at 1 cm/s from its true pose (unsigned, signed by a car's certificate,
      and the real Eye's signed pose with the walk written in) [<= 0.02 m]
  intersection_*               a real intersection run (tools/demo --mission intersection:
      4 cars, autodrive-marl with its shield, the real Eye, INTER_EPISODES episodes of the same
      seed) under IntersectionAttacker (ghost cars on V2V, real states replayed 1 s later, a
      revoked car certificate, forged light commands): collisions [0], episodes not run [0],
      the MARL nodes' own per-peer accounts' time held by ghosts (ghost_extra_stop_s) and
      ghosts in their peer tables [0 s], real cars' states accepted beyond their originals
      (replayed_v2v_accepted) [0], states of the revoked certificate accepted [0], OFF light
      states (forged_light_state_changes) [0], real_eye [true], eye_sync_give_ups [0]; reported:
      the MARL nodes' V2V refusals by reason, episodes and successes
Progress on stderr; the last line is one JSON object. Usage: tools/bench v2x [--help]"""

from __future__ import annotations

import argparse
import bisect
import ctypes
import json
import math
import os
import select
import statistics
import subprocess
import sys
import threading
import multiprocessing
import tempfile
import time
from pathlib import Path
from typing import Any

from autodrive.bench import Progress, build_dir, print_figures
from autodrive.bench.goals import at_most, equals, judge
from autodrive.core import seeds, settings
from autodrive.hil.city import peer_account
from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.channels import channel

log = Progress("v2x")
# LCM ports 7873 (lights), 7874 (smart city) and 7875 (intersection), moved by the instance
# (AUTODRIVE_INSTANCE N: + N * port_step), so that two sessions' benches never hear each other
PORT_SHIFT = settings.instance().number * settings.instance().port_step
PORT = 7873 + PORT_SHIFT
URL = f"udpm://239.255.76.67:{PORT}?ttl=0"
CARS, BUS_HZ = 16, 20.0
LIGHT = 1  # Intersection School's light 1: RED <-> OFF never conflicts
# Issue 33's goals; every one a figure at or under its bound (a missing figure fails).
GOALS = {
    name: at_most(name, bound)
    for name, bound in {
        "forged_light_state_changes": 0,
        "replayed_v2v_accepted": 0,
        "replayed_light_cmd_accepted": 0,
        "revoked_accepted_after_1s": 0,
        "brute_force_accepted": 0,
        "brute_force_user_latency_ratio": 2.0,
        "bus16_cpu_share": 0.05,
        "forged_green_red_violations": 0,
        "ghost_car_extra_stop_s": 0.0,
        "ghost_in_peer_table_s": 0.0,
        "eye_walk_ekf_drift_m": 0.02,
        "city_eye_sync_give_ups": 0,
        "intersection_eye_sync_give_ups": 0,
        "intersection_collisions": 0,
        "intersection_episodes_not_run": 0,
        "intersection_ghost_extra_stop_s": 0.0,
        "intersection_ghost_in_peer_table_s": 0.0,
        "intersection_replayed_v2v_accepted": 0,
        "intersection_revoked_accepted": 0,
        "intersection_forged_light_state_changes": 0,
    }.items()
} | {
    # the runs' poses came from the real Eye (rendered images, libapriltag), not a stand-in
    "city_real_eye": equals("city_real_eye", True),
    "intersection_real_eye": equals("intersection_real_eye", True),
}
UNSEEDED = seeds.unseeded("scripted attacks only (no smart-city runs)")


def percentile(values: list[float], q: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, int(q * len(ordered)))]


class CLib:
    """The receivers' C library through ctypes (signer and verifier of one key folder)."""

    def __init__(self, build: Path, key_dir: Path) -> None:
        lib = ctypes.CDLL(str(build / "lib" / "libautodrive_v2x_auth.so"))
        lib.v2x_verifier_create.restype = ctypes.c_void_p
        lib.v2x_signer_load.restype = ctypes.c_void_p
        lib.v2x_role_mask.restype = ctypes.c_uint
        lib.v2x_sign.restype = ctypes.c_size_t
        lib.v2x_sign.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p,
            ctypes.c_size_t, ctypes.c_int64, ctypes.c_char_p, ctypes.c_size_t]  # fmt: skip
        lib.v2x_verify.argtypes = [ctypes.c_void_p, ctypes.c_char_p, ctypes.c_char_p,
            ctypes.c_size_t, ctypes.c_char_p, ctypes.c_size_t, ctypes.c_uint, ctypes.c_char_p,
            ctypes.c_int64, ctypes.c_int64, ctypes.c_void_p]  # fmt: skip
        self.lib, self.key_dir = lib, key_dir
        self.car_mask = lib.v2x_role_mask(b"car")

    def verifier(self) -> int:
        err = ctypes.create_string_buffer(512)
        v = self.lib.v2x_verifier_create(str(self.key_dir).encode(), err, 512)
        if not v:
            raise RuntimeError(err.value.decode())
        return int(v)

    def signer(self, name: str) -> int:
        err = ctypes.create_string_buffer(512)
        s = self.lib.v2x_signer_load(str(self.key_dir).encode(), name.encode(), err, 512)
        if not s:
            raise RuntimeError(err.value.decode())
        return int(s)


def bus_stream(types: Any, clib: CLib) -> list[tuple[str, bytes, bytes, int, float]]:
    """2 s of a 16-car V2V bus at 20 Hz, signed by the C library: (name, payload, auth,
    sender_utime, sign time [us])."""
    signers = {f"NIGEL{i}": clib.signer(f"NIGEL{i}") for i in range(1, CARS + 1)}
    out = []
    envelope = ctypes.create_string_buffer(256)
    for k in range(int(2 * BUS_HZ)):
        t_us = 10_000_000 + int(k * 1e6 / BUS_HZ)
        for name, s in signers.items():
            m = types.v2v_state_t()
            m.utime, m.seq, m.vehicle, m.route, m.x_m = t_us, k, name, "", 0.1 * k
            payload = v2x_auth.unsigned_payload(m)
            t0 = time.perf_counter_ns()
            n = clib.lib.v2x_sign(s, b"V2V", payload, len(payload), t_us, envelope, 256)
            out.append((name, payload, envelope.raw[:n], t_us, (time.perf_counter_ns() - t0) / 1e3))
    return out


def crypto_and_replay(types: Any, clib: CLib) -> dict[str, Any]:
    stream = bus_stream(types, clib)
    v = clib.verifier()
    wall = int(time.time())
    verify_us: list[float] = []
    cpu0 = time.process_time()
    accepted = 0
    for name, payload, auth, t_us, _ in stream:
        t0 = time.perf_counter_ns()
        r = clib.lib.v2x_verify(v, b"V2V", payload, len(payload), auth, len(auth), clib.car_mask,
                                name.encode(), t_us, wall, None)  # fmt: skip
        verify_us.append((time.perf_counter_ns() - t0) / 1e3)
        accepted += r == 0
    cpu_s = time.process_time() - cpu0
    # a receiver checks the 15 others' states: (CARS - 1) / CARS of the stream, over 2 s of bus
    share = cpu_s * (CARS - 1) / CARS / 2.0
    replayed = 0
    for name, payload, auth, t_us, _ in stream:  # the same bytes 1 s later on its clock
        r = clib.lib.v2x_verify(v, b"V2V", payload, len(payload), auth, len(auth), clib.car_mask,
                                name.encode(), t_us + 1_000_000, wall, None)  # fmt: skip
        replayed += r == 0
    log(f"{len(stream)} V2V messages: {accepted} accepted first, {replayed} of their replays")
    return {
        "bus_messages": len(stream),
        "bus_accepted_first": accepted,
        "replayed_v2v_accepted": replayed,
        "verify_us_p50": round(percentile(verify_us, 0.5), 1),
        "verify_us_p99": round(percentile(verify_us, 0.99), 1),
        "sign_us_p50": round(percentile([s[4] for s in stream], 0.5), 1),
        "bus16_cpu_share": round(share, 4),
    }


class LightBench:
    """The real simulator's lights, commanded and watched on real LCM."""

    def __init__(self, build: Path, types: Any, run_dir: str) -> None:
        self.types = types
        self.lc = lcmtypes.bus(URL)
        self.states: list[tuple[float, int, int]] = []  # wall time, light, state
        self.clock = v2x_auth.BusClock()
        self.lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), self._on_state)
        self.sim = subprocess.Popen(
            [str(build / "bin" / "autodrive-sim"), "--map", "intersection_school", "--rtf", "1",
             "--no-pty", "--no-lidar", "--quiet", "--run-dir", run_dir, "--lcm-url", URL],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )  # fmt: skip

    def _on_state(self, _c: str, data: bytes) -> None:
        m = self.types.traffic_light_state_t.decode(data)
        self.states.append((time.monotonic(), m.light_id, m.state))
        self.clock.heard(m.utime)

    def pump(self, seconds: float) -> None:
        end = time.monotonic() + seconds
        while time.monotonic() < end:
            if select.select([self.lc.fileno()], [], [], 0.01)[0]:
                self.lc.handle()

    def command(self, state: int, signer: v2x_auth.MessageSigner | None) -> Any:
        msg = self.types.traffic_light_command_t()
        msg.utime, msg.light_id, msg.state, msg.duration_s = self.clock.now_us(), LIGHT, state, 0.0
        if signer is not None:
            signer.sign(channel("TRAFFIC_LIGHT_COMMAND"), msg, self.clock.now_us())
        return msg

    def publish(self, msg: Any) -> None:
        self.lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), msg.encode())

    def changes_to(self, state: int, since: float) -> int:
        """State messages of LIGHT showing `state` after `since` (wall, monotonic)."""
        return sum(1 for t, i, s in self.states if i == LIGHT and s == state and t > since)

    def stop(self) -> str:
        self.sim.terminate()
        _, err = self.sim.communicate(timeout=30)
        return str(err)


def light_attacks(build: Path, types: Any, key_dir: Path) -> dict[str, Any]:
    State = types.traffic_light_state_t
    scm = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM", key_dir))
    car = v2x_auth.MessageSigner(v2x_ca.load_identity("NIGEL1", key_dir))
    with tempfile.TemporaryDirectory(prefix="bench-v2x-sim-") as run_dir:
        b = LightBench(build, types, run_dir)
        try:
            b.pump(3.0)
            if not b.states:
                raise RuntimeError("the simulator publishes no light states")
            b.publish(b.command(State.RED, scm))  # the SCM holds light 1 red
            b.pump(1.0)
            t_attack = time.monotonic()
            for variant in ("unsigned", "altered", "wrong_role"):
                for _ in range(30):  # 10 Hz for 3 s: OFF for light 1
                    if variant == "unsigned":
                        msg = b.command(State.OFF, None)
                    elif variant == "altered":
                        msg = b.command(State.RED, scm)
                        msg.state = State.OFF  # RED signed, OFF sent
                    else:
                        msg = b.command(State.OFF, car)
                    b.publish(msg)
                    b.pump(0.1)
            forged = b.changes_to(State.OFF, t_attack)
            log(f"forged light commands: {forged} OFF states of light {LIGHT}")
            # replay: a signed OFF obeyed, RED again, then the OFF bytes 1 s later
            off = b.command(State.OFF, scm)
            b.publish(off)
            b.pump(0.5)
            legit_off = b.changes_to(State.OFF, t_attack) - forged
            b.publish(b.command(State.RED, scm))
            b.pump(1.0)
            t_replay = time.monotonic()
            b.publish(off)
            b.pump(1.0)
            replayed = b.changes_to(State.OFF, t_replay)
            log(f"signed OFF obeyed: {legit_off > 0}; its replay 1 s later: {replayed} OFF states")
            # revocation: a second scm toggles the light at 10 Hz; revoked mid-way
            ca = v2x_ca.Authority(key_dir)
            ca.issue("SCM2", "scm", 1)
            rogue = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM2", key_dir))
            t_revoke = 0.0
            for k in range(40):
                if k == 15:
                    ca.revoke(["SCM2"])
                    t_revoke = time.monotonic()
                b.publish(b.command(State.OFF if k % 2 else State.RED, rogue))
                b.pump(0.1)
            # the light's states from 1 s after the revocation on (0.2 s more: a command sent
            # just before that second may still be in flight)
            after = [s for t, i, s in b.states if i == LIGHT and t > t_revoke + 1.2]
            changes = sum(1 for x, y in zip(after, after[1:]) if x != y)
            log(f"revoked scm: {changes} light changes more than 1 s after the revocation")
        finally:
            err = b.stop()
    dropped = [ln for ln in err.splitlines() if "TRAFFIC_LIGHT_COMMAND dropped" in ln]
    for ln in dropped[:8]:
        log(f"simulator: {ln}")
    return {
        "forged_light_state_changes": forged,
        "signed_light_cmd_obeyed": legit_off > 0,
        "replayed_light_cmd_accepted": replayed,
        "revoked_accepted_after_1s": changes,
    }


def brute_force(build: Path, tmp: Path) -> dict[str, Any]:
    from autodrive.scm.testkit import Attacker, Client, Server, add_user, self_signed_cert

    db = f"sqlite:///{tmp / 'scm.sqlite'}"
    add_user(db, "alice", "operator", "correct-horse-1")
    for u in ("bob", "carol"):
        add_user(db, u, "viewer", f"{u}-password-2")
    cert, key = self_signed_cert(tmp)
    server = Server(db, URL, str(build), tls=(cert, key))
    try:
        users = []
        for u in ("bob", "carol"):
            c = Client(server.url, cafile=cert)
            c.login(u, f"{u}-password-2")
            users.append(c)

        def sample(n: int) -> list[float]:
            out = []
            for _ in range(n):
                for c in users:
                    t0 = time.perf_counter()
                    code, _ = c.call("GET", "/api/state")
                    out.append(time.perf_counter() - t0)
                    if code != 200:
                        raise RuntimeError(f"a user's GET /api/state: {code}")
            return out

        quiet = statistics.median(sample(40))
        guesses = [f"guess-{i}" for i in range(999)]
        guesses.insert(500, "correct-horse-1")
        answers: multiprocessing.Queue[dict[int, int]] = multiprocessing.Queue()

        def attack() -> None:  # a process of its own: it does not share this one's GIL
            a = Attacker(server.url, cafile=cert)
            answers.put(a.brute_force("alice", guesses))
            a.close()

        attacker = multiprocessing.get_context("fork").Process(target=attack)
        attacker.start()
        loaded: list[float] = []
        while attacker.is_alive() and answers.empty():
            loaded += sample(1)
        result = answers.get(timeout=600)
        attacker.join()
        ratio = statistics.median(loaded) / quiet if loaded else float("nan")
        log(f"brute force: {result}; users' median {quiet * 1e3:.1f} ms quiet, "
            f"{statistics.median(loaded) * 1e3:.1f} ms under attack")  # fmt: skip
    finally:
        server.stop()
    return {
        "brute_force_accepted": result.get(200, 0),
        "brute_force_refused_429": result.get(429, 0),
        "brute_force_user_latency_ratio": round(ratio, 2),
        "users_median_ms_quiet": round(quiet * 1e3, 2),
    }


CITY_PORT, CITY_CARS, CITY_SIM_S = 7874 + PORT_SHIFT, 3, 30
# the smart-city and intersection runs' seed: V2X_BENCH_SEED, default the next unused of the
# evaluation block kept for this bench (seeds.V2X_BENCH_NEXT_SEED of seeds.V2X_BENCH_SEEDS; a
# seed anybody traced moves to development: take the next)
CITY_SEED = seeds.require(
    int(os.environ.get("V2X_BENCH_SEED", seeds.V2X_BENCH_NEXT_SEED)), ("evaluation",),
    "V2X_BENCH_SEED")  # fmt: skip
CITY_URL = f"udpm://239.255.76.67:{CITY_PORT}?ttl=0"
STOPPED_M_S = 0.01  # a car slower than this is stopped [m/s]
# The real Eye (the simulator's rendered overhead cameras, autodrive-eye with libapriltag), in
# lockstep with the simulator (autodrive-sim --eye-sync): its poses at capture + 15 ms of sim
# time at any load, so that runs of one seed repeat on the sim clock. (Until 2026-12-03 the
# bench ran the Eye stand-in, from before the Eye was in lockstep.)
CITY_EYE = "cameras"
WALK_M_S = 0.01  # the forged Eye poses' walk away from the true pose [m/s of sim time]


REPLAY_LATE_US = 1_000_000  # real cars' V2V states replayed this late [us, sim]


def rogue_signers(names: list[str], folder: Path) -> dict[str, v2x_auth.MessageSigner]:
    """Signers under certificates of another authority (a CA of their own in folder) for names."""
    rogue = v2x_ca.Authority(folder)
    rogue.init()
    for name in names:
        rogue.issue(name, "car", 1)
    return {n: v2x_auth.MessageSigner(v2x_ca.load_identity(n, folder)) for n in names}


GHOST_AHEAD_M = 0.3  # [m] a ghost car stands this far ahead of the real car it copies


def ghost_ahead(types: Any, own: Any, name: str) -> Any:
    """A standing car named name, GHOST_AHEAD_M ahead of the real state own, unsigned."""
    g = types.v2v_state_t.decode(own.encode())
    g.vehicle, g.speed_m_s, g.auth, g.auth_len = name, 0.0, b"", 0
    g.x_m += GHOST_AHEAD_M * math.cos(own.yaw_rad)
    g.y_m += GHOST_AHEAD_M * math.sin(own.yaw_rad)
    return g


class CityAttacker:
    """Beside a real smart-city run: for each car, at 50 Hz of wall time, forged GREEN advisories
    (unsigned; the real signed one with RED made GREEN; signed by a car's certificate), ghost
    cars standing 0.3 m ahead of it on V2V (unsigned as NIGEL9; under another real car's name
    signed by this car's own certificate; as that real car and as NIGEL9 with another
    authority's certificates), every real car's V2V states replayed REPLAY_LATE_US later, and
    Eye poses walking away from the car's true pose at WALK_M_S of sim time (unsigned; signed by
    a car's certificate; the real Eye's last signed pose with the walk written in)."""

    def __init__(self, types: Any, key_dir: Path, rogue_dir: Path) -> None:
        self.types = types
        self.lc = lcmtypes.bus(CITY_URL)
        self.car_signers = {
            f"NIGEL{i}": v2x_auth.MessageSigner(v2x_ca.load_identity(f"NIGEL{i}", key_dir))
            for i in range(1, CITY_CARS + 1)
        }
        self.rogue = rogue_signers([*self.car_signers, "NIGEL9"], rogue_dir)
        self.replays: list[tuple[int, bytes]] = []  # (due [us, sim], a real car's V2V bytes)
        self.sim_us = 0  # the latest sim time heard (GROUND_TRUTH) [us]
        self.own_v2v: dict[bytes, None] = {}  # envelopes this attacker sent on V2V, oldest first
        self.advice: dict[str, Any] = {}
        self.states: dict[str, Any] = {}
        self.truth: dict[str, Any] = {}  # each car's latest GROUND_TRUTH
        self.eye: dict[str, Any] = {}  # each car's latest real (signed) Eye pose
        self.walk_from_us: dict[str, int] = {}  # each car's walk start [us, sim]
        self.forged_auth: set[bytes] = set()  # envelopes of this attacker's own Eye poses
        self.sent = 0
        self.stop = threading.Event()
        for car in self.car_signers:
            self.lc.subscribe(channel("V2I", car), self._on_advice)
            self.lc.subscribe(channel("GROUND_TRUTH", car), self._on_truth)
            self.lc.subscribe(channel("POSE_EYE", car), self._on_eye)
        self.lc.subscribe(channel("V2V"), self._on_v2v)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _on_advice(self, _c: str, data: bytes) -> None:
        m = self.types.v2i_advisory_t.decode(data)
        self.advice[m.vehicle] = m

    def _on_v2v(self, _c: str, data: bytes) -> None:
        m = self.types.v2v_state_t.decode(data)
        auth = v2x_auth.auth_of(m)
        # a real car's own state: signed, and not this attacker's (its ghosts, its replays)
        if m.vehicle in self.car_signers and auth and auth not in self.own_v2v:
            self.states[m.vehicle] = m
            self.replays.append((m.utime + REPLAY_LATE_US, data))

    def _on_truth(self, _c: str, data: bytes) -> None:
        m = self.types.ground_truth_t.decode(data)
        self.truth[m.vehicle] = m
        self.sim_us = max(self.sim_us, m.utime)
        self.walk_from_us.setdefault(m.vehicle, m.utime)

    def _on_eye(self, _c: str, data: bytes) -> None:
        m = self.types.pose2d_t.decode(data)
        auth = v2x_auth.auth_of(m)
        if auth and auth not in self.forged_auth:  # the real Eye's (not this attacker's own)
            self.eye[m.vehicle] = m

    def _walk(self, car: str, signer: v2x_auth.MessageSigner) -> None:
        """Eye poses of car WALK_M_S * (sim time since the walk began) off its true pose."""
        truth = self.truth.get(car)
        if truth is None:
            return
        off_m = WALK_M_S * (truth.utime - self.walk_from_us[car]) * 1e-6
        chan = channel("POSE_EYE", car)
        p = self.types.pose2d_t()
        p.utime, p.vehicle, p.frame_id = truth.utime, car, "map"
        p.source = self.types.pose2d_t.SOURCE_EYE
        p.x_m = truth.position_m[0] + off_m * math.cos(truth.yaw_rad + math.pi / 2)
        p.y_m = truth.position_m[1] + off_m * math.sin(truth.yaw_rad + math.pi / 2)
        p.yaw_rad = truth.yaw_rad
        self._publish(chan, p)  # unsigned
        signed = signer.sign(chan, p, truth.utime)  # a car's certificate
        if len(self.forged_auth) > 10_000:
            self.forged_auth.clear()
        self.forged_auth.add(v2x_auth.auth_of(signed))
        self._publish(chan, signed)
        real = self.eye.get(car)
        if real is not None:  # the Eye's signature kept, the walk written in: a forgery
            real.x_m, real.y_m = p.x_m, p.y_m
            self.forged_auth.add(v2x_auth.auth_of(real))
            self._publish(chan, real)

    def _publish(self, chan: str, msg: Any) -> None:
        self.lc.publish(chan, msg.encode())
        self.sent += 1

    def _run(self) -> None:
        green = self.types.traffic_light_state_t.GREEN
        next_t = time.monotonic()
        while not self.stop.is_set():
            if select.select([self.lc.fileno()], [], [], max(0.0, next_t - time.monotonic()))[0]:
                self.lc.handle()
                continue
            next_t += 0.02
            for car, signer in self.car_signers.items():
                self._walk(car, signer)
                real = self.advice.get(car)
                if real is not None:
                    chan = channel("V2I", car)
                    altered = self.types.v2i_advisory_t.decode(real.encode())
                    altered.light_state = green  # the SCM's signature kept: a forgery
                    self._publish(chan, altered)
                    unsigned = self.types.v2i_advisory_t.decode(real.encode())
                    unsigned.light_state, unsigned.auth, unsigned.auth_len = green, b"", 0
                    self._publish(chan, unsigned)
                    self._publish(chan, signer.sign(chan, unsigned, real.utime))  # a car's cert
                self._ghosts(car, signer)
            self._replay()

    def _ghosts(self, car: str, signer: v2x_auth.MessageSigner) -> None:
        """Ghost cars 0.3 m ahead of car, from its latest V2V state."""
        own = self.states.get(car)
        if own is None:
            return
        other = next(c for c in self.car_signers if c != car)
        for name, sign in (("NIGEL9", None), (other, signer), (other, self.rogue[other]),
                           ("NIGEL9", self.rogue["NIGEL9"])):  # fmt: skip
            g = ghost_ahead(self.types, own, name)
            if sign is not None:
                sign.sign(channel("V2V"), g, own.utime)
                self._sent_v2v(v2x_auth.auth_of(g))
            self._publish(channel("V2V"), g)

    def _replay(self) -> None:
        """The real cars' states whose replay is due on the sim clock, byte for byte."""
        while self.replays and self.replays[0][0] <= self.sim_us:
            data = self.replays.pop(0)[1]
            self._sent_v2v(v2x_auth.auth_of(self.types.v2v_state_t.decode(data)))
            self.lc.publish(channel("V2V"), data)
            self.sent += 1

    def _sent_v2v(self, auth: bytes) -> None:
        """Remembers an envelope this attacker sends on V2V (the last 20 000), so that its echo
        on the bus is not taken for a real car's state."""
        self.own_v2v[auth] = None
        if len(self.own_v2v) > 20_000:
            del self.own_v2v[next(iter(self.own_v2v))]

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=10)


def ekf_error_m(log_path: Path, types: Any, last_s: float = 10.0) -> float:
    """The worst car's median EKF map error [m]: each POSE_MAP against the car's
    GROUND_TRUTH at its stamp (the latest at or before it), over the last `last_s` of the run's
    sim time."""
    truth: dict[str, list[tuple[int, float, float]]] = {}
    maps: list[Any] = []
    for e in lcmtypes.events(log_path):
        if e.channel.endswith("_GROUND_TRUTH"):
            g = types.ground_truth_t.decode(e.data)
            truth.setdefault(g.vehicle, []).append((g.utime, g.position_m[0], g.position_m[1]))
        elif e.channel.endswith("_POSE_MAP"):
            maps.append(types.odometry_t.decode(e.data))
    tracks = {v: sorted(t) for v, t in truth.items()}
    errors: dict[str, list[tuple[int, float]]] = {}
    for m in maps:
        track = tracks.get(m.vehicle, [])
        k = bisect.bisect_right(track, (m.utime, math.inf, math.inf)) - 1
        if k >= 0:
            _, tx, ty = track[k]
            errors.setdefault(m.vehicle, []).append((m.utime, math.hypot(m.x_m - tx, m.y_m - ty)))
    if not errors:
        raise RuntimeError(f"{log_path}: no POSE_MAP beside GROUND_TRUTH")
    worst = 0.0
    for samples in errors.values():
        end_us = samples[-1][0]
        worst = max(worst, statistics.median(d for t, d in samples if t >= end_us - last_s * 1e6))
    return worst


def stopped_s(log_path: Path, types: Any) -> float:
    """Sim time the cars spent stopped, all cars [s], from the run's GROUND_TRUTH."""
    last: dict[str, tuple[int, float]] = {}
    total = 0.0
    for e in lcmtypes.events(log_path):
        if not e.channel.endswith("_GROUND_TRUTH"):
            continue
        m = types.ground_truth_t.decode(e.data)
        speed = math.hypot(m.linear_velocity_m_s[0], m.linear_velocity_m_s[1])
        prev = last.get(m.vehicle)
        if prev is not None and prev[1] < STOPPED_M_S and m.utime > prev[0]:
            total += (m.utime - prev[0]) * 1e-6
        last[m.vehicle] = (m.utime, speed)
    return total


def smart_city_run(build: Path, out: Path) -> dict[str, Any]:
    cmd = [sys.executable, "-m", "autodrive.hil.demo", "--mission", "smart-city", "--headless",
           "--build", str(build), "--out", str(out), "--seed", str(CITY_SEED), "--timeout", "900",
           "--sim-seconds", str(CITY_SIM_S), "--advisory", "scm", "--lcm-url", CITY_URL,
           "--eye", CITY_EYE]  # fmt: skip
    subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, timeout=1100)
    report: dict[str, Any] = json.loads((out / "report.json").read_text())
    return report


def refusals(out: Path) -> str:
    """The city drivers' last words on what they refused (their logs in the run's folder)."""
    lines = []
    for f in sorted(out.glob("city-driver*.log")):
        lines += [ln.split("refused V2X messages: ")[1] for ln in f.read_text().splitlines()
                  if "refused V2X messages: " in ln]  # fmt: skip
    return " | ".join(lines)


def ghost_figures(out: Path, key_dir: Path) -> dict[str, Any]:
    """The ghosts' charges in the city drivers' per-peer accounts (their logs in out): a real car
    is its name under its own certificate of this run's CA; every other peer is a ghost. A
    driver without an account (it did not stop cleanly) leaves the figures missing: failed."""
    real = {
        f"NIGEL{i}": v2x_ca.load_identity(f"NIGEL{i}", key_dir).cert.serial
        for i in range(1, CITY_CARS + 1)
    }
    logs = sorted(out.glob("city-driver*.log"))
    try:
        if len(logs) != CITY_CARS:
            raise peer_account.AccountError(f"{out}: {len(logs)} city-driver logs, not {CITY_CARS}")
        c = peer_account.charges(logs, real)
    except peer_account.AccountError as e:
        log(f"no ghost figures: {e}")
        return {"ghost_car_extra_stop_s": None, "ghost_in_peer_table_s": None}
    log(f"peer accounts: ghosts held the cars {c['ghost_held_s']:.3f} s, were in a peer table "
        f"{c['ghost_in_table_s']:.3f} s ({c['ghost_accepted']} states accepted); real peers "
        f"held them {c['real_peer_held_s']:.1f} s")  # fmt: skip
    return {
        "ghost_car_extra_stop_s": round(c["ghost_held_s"], 3),
        "ghost_in_peer_table_s": round(c["ghost_in_table_s"], 3),
        "ghost_v2v_accepted": c["ghost_accepted"],
        "city_held_by_real_peers_s": round(c["real_peer_held_s"], 1),
    }


def give_ups(reports: list[dict[str, Any]]) -> int | None:
    """The runs' Eye give-ups in all (pose_source.eye_sync_give_ups); None when any run does not
    say (not in lockstep, or its count unknown): the figure is then missing, its goal failed."""
    counts = [r.get("eye_sync_give_ups") for r in reports]
    if any(not isinstance(c, int) or c < 0 for c in counts):
        return None
    return sum(c for c in counts if isinstance(c, int))


def smart_city_attacks(build: Path, types: Any, key_dir: Path, tmp: Path) -> dict[str, Any]:
    quiet_stops, quiet_ekf, quiet_sources = [], [], []
    quiet_reports: list[dict[str, Any]] = []
    for k in (1, 2):  # two quiet runs: their spread is the run-to-run difference
        log(f"smart-city run, quiet #{k} ({CITY_SIM_S} s of sim time, seed {CITY_SEED}, "
            f"--eye {CITY_EYE})")  # fmt: skip
        quiet = smart_city_run(build, tmp / f"quiet{k}")
        quiet_sources.append(quiet.get("pose_source"))
        quiet_reports.append(quiet)
        quiet_stops.append(stopped_s(tmp / f"quiet{k}" / "run.lcmlog", types))
        quiet_ekf.append(ekf_error_m(tmp / f"quiet{k}" / "run.lcmlog", types))
    attacker = CityAttacker(types, key_dir, tmp / "rogue-ca")
    log("smart-city run, under forged GREEN advisories and ghost cars")
    try:
        attacked = smart_city_run(build, tmp / "attacked")
    finally:
        attacker.close()
    stop_quiet = max(quiet_stops)
    stop_attacked = stopped_s(tmp / "attacked" / "run.lcmlog", types)
    ekf_attacked = ekf_error_m(tmp / "attacked" / "run.lcmlog", types)
    refused = refusals(tmp / "attacked")
    log(f"the city drivers refused: {refused}")
    log(f"{attacker.sent} hostile messages; red-light violations {attacked['red_light_violations']}"
        f" (quiet {quiet['red_light_violations']}); stopped {stop_attacked:.1f} s "
        f"(quiet {stop_quiet:.1f} s, all cars)")  # fmt: skip
    return {
        **ghost_figures(tmp / "attacked", key_dir),
        "city_seed": CITY_SEED,
        # which poses the cars' EKFs fused, as each run's report says (None: it does not say)
        "city_pose_source": attacked.get("pose_source"),
        "city_pose_source_quiet": quiet_sources,
        # the simulator gave the Eye up (a run that then depended on wall time), all 3 runs
        "city_eye_sync_give_ups": give_ups(quiet_reports + [attacked]),
        "city_real_eye": all(src == "eye" for src in [*quiet_sources, attacked.get("pose_source")]),
        "city_hostile_messages": attacker.sent,
        "forged_green_red_violations": attacked["red_light_violations"],
        "city_collisions_under_attack": attacked["collisions"],
        "city_stopped_s_quiet": [round(q, 1) for q in quiet_stops],
        "city_drivers_refused": refused,
        "city_stopped_s_attacked": round(stop_attacked, 1),
        # no ghost figure: the run-to-run spread of the quiet runs is as large (informational)
        "city_stop_difference_s_info": round(stop_attacked - stop_quiet, 1),
        "city_ekf_error_m_quiet": [round(q, 4) for q in quiet_ekf],
        "city_ekf_error_m_attacked": round(ekf_attacked, 4),
        "eye_walk_ekf_drift_m": round(max(0.0, ekf_attacked - max(quiet_ekf)), 4),
    }


INTER_PORT, INTER_CARS = 7875 + PORT_SHIFT, 4
INTER_URL = f"udpm://239.255.76.67:{INTER_PORT}?ttl=0"
# episodes of the intersection run (each a fresh simulator, four runtimes, four autodrive-marl)
INTER_EPISODES = int(os.environ.get("V2X_BENCH_INTERSECTION_EPISODES", "5"))
INTER_TIMEOUT_S = 3600.0  # the intersection run's hang guard [s wall]; the run is on sim time
# A car certificate of this run's CA that no car of the intersection run holds, revoked before
# the run: its ghosts are sent from REVOKED_QUIET_S of wall time after the revocation on.
REVOKED_CAR, REVOKED_SCM = "NIGEL12", "SCM3"
REVOKED_QUIET_S = 1.2  # more than the goal's 1 s, and 0.2 s for a reload in flight [s wall]
NEW_EPISODE_BACK_US = 2_000_000  # a real car's V2V stamp this far back: a new simulator [us]


class IntersectionAttacker:
    """Beside a real intersection run (tools/demo --mission intersection): on every V2V state a
    real car sends, ghost cars 0.3 m ahead of it (unsigned as NIGEL9; another real car's name
    signed by this car's certificate; that car and NIGEL9 under another authority's
    certificates; REVOKED_CAR under its revoked certificate of this CA), and that state replayed
    byte for byte REPLAY_LATE_US of sim time later (within its episode: a new simulator's clock
    starts again); on every light state of the simulator, that light commanded OFF (a state its
    program never shows) unsigned, as an scm-signed RED altered to OFF, signed by a car's
    certificate and by the revoked scm certificate REVOKED_SCM. Everything follows the sim
    clock (the real messages it answers), so the load changes only the wall time."""

    def __init__(self, types: Any, key_dir: Path, rogue_dir: Path, revoked_at: float) -> None:
        self.types = types
        self.lc = lcmtypes.bus(INTER_URL)
        self.cars = [f"NIGEL{i}" for i in range(1, INTER_CARS + 1)]
        self.car_signers = {
            c: v2x_auth.MessageSigner(v2x_ca.load_identity(c, key_dir)) for c in self.cars
        }
        self.rogue = rogue_signers([*self.cars, "NIGEL9"], rogue_dir)
        self.revoked_car = v2x_auth.MessageSigner(v2x_ca.load_identity(REVOKED_CAR, key_dir))
        self.revoked_scm = v2x_auth.MessageSigner(v2x_ca.load_identity(REVOKED_SCM, key_dir))
        self.scm = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM", key_dir))
        self.revoked_from = revoked_at + REVOKED_QUIET_S  # [s, time.monotonic]
        self.replays: list[tuple[int, bytes]] = []  # (due [us, sim], a real car's V2V bytes)
        self.own_v2v: set[bytes] = set()  # every envelope this attacker sent on V2V
        self.seen: set[bytes] = set()  # every real car's envelope heard (an original once)
        self.sim_us = -1  # the latest original's stamp [us, sim] of the episode running
        self.sent: dict[str, int] = {}  # by attack [count]
        self.stop = threading.Event()
        self.lc.subscribe(channel("V2V"), self._on_v2v)
        self.lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), self._on_light)
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self) -> None:
        while not self.stop.is_set():
            if select.select([self.lc.fileno()], [], [], 0.05)[0]:
                self.lc.handle()

    def _publish(self, attack: str, chan: str, msg: Any) -> None:
        self.lc.publish(chan, msg.encode())
        self.sent[attack] = self.sent.get(attack, 0) + 1

    def _on_v2v(self, _c: str, data: bytes) -> None:
        m = self.types.v2v_state_t.decode(data)
        auth = v2x_auth.auth_of(m)
        if m.vehicle not in self.car_signers or not auth or auth in self.own_v2v:
            return
        if auth in self.seen:
            return  # a replay of ours echoed back
        self.seen.add(auth)
        if m.utime < self.sim_us - NEW_EPISODE_BACK_US:
            self.replays.clear()  # a new simulator (its clock started again): replays stay
            self.sim_us = -1  # within their episode
        self.sim_us = max(self.sim_us, m.utime)
        self.replays.append((m.utime + REPLAY_LATE_US, data))
        while self.replays and self.replays[0][0] <= self.sim_us:
            old = self.replays.pop(0)[1]
            self.lc.publish(channel("V2V"), old)
            self.sent["v2v_replayed"] = self.sent.get("v2v_replayed", 0) + 1
        self._ghosts(m)

    def _ghosts(self, own: Any) -> None:
        signer = self.car_signers[own.vehicle]
        other = next(c for c in self.cars if c != own.vehicle)
        variants: list[tuple[str, str, v2x_auth.MessageSigner | None]] = [
            ("ghost_unsigned", "NIGEL9", None),
            ("ghost_wrong_name", other, signer),
            ("ghost_other_authority", other, self.rogue[other]),
            ("ghost_other_authority", "NIGEL9", self.rogue["NIGEL9"]),
        ]
        if time.monotonic() >= self.revoked_from:
            variants.append(("ghost_revoked_certificate", REVOKED_CAR, self.revoked_car))
        for attack, name, sign in variants:
            g = ghost_ahead(self.types, own, name)
            if sign is not None:
                sign.sign(channel("V2V"), g, own.utime)
                self.own_v2v.add(v2x_auth.auth_of(g))
            self._publish(attack, channel("V2V"), g)

    def _on_light(self, _c: str, data: bytes) -> None:
        m = self.types.traffic_light_state_t.decode(data)
        State = self.types.traffic_light_state_t
        chan = channel("TRAFFIC_LIGHT_COMMAND")

        def command(state: int) -> Any:
            c = self.types.traffic_light_command_t()
            c.utime, c.light_id, c.state, c.duration_s = m.utime, m.light_id, state, 0.0
            return c

        self._publish("light_unsigned", chan, command(State.OFF))
        altered = self.scm.sign(chan, command(State.RED), m.utime)
        altered.state = State.OFF  # RED signed, OFF sent
        self._publish("light_altered", chan, altered)
        car = self.car_signers[self.cars[0]]
        self._publish("light_wrong_role", chan, car.sign(chan, command(State.OFF), m.utime))
        if time.monotonic() >= self.revoked_from:
            revoked = self.revoked_scm.sign(chan, command(State.OFF), m.utime)
            self._publish("light_revoked_certificate", chan, revoked)

    def close(self) -> None:
        self.stop.set()
        self.thread.join(timeout=10)


def v2v_originals(
    log_path: Path, types: Any, cars: list[str], own: set[bytes]
) -> tuple[list[dict[str, int]], int]:
    """Per episode (in the order the simulators ran), per real car: the V2V states it sent
    [count], from lcm-logger's log of the run, and how many of them the log holds. A car's
    runtime numbers its states 0, 1, 2, ... (v2v_state_t.seq, from its start, one runtime per
    episode), so it sent its highest logged seq + 1: a state the logger lost under load (UDP)
    still counts. Each signed envelope once, none of the attacker's own (own: its envelopes);
    a stamp more than NEW_EPISODE_BACK_US behind the episode's latest opens the next episode (a
    new simulator's clock starts again; a replay, a repeated envelope, never does)."""
    episodes: list[dict[str, int]] = []
    seen: set[bytes] = set()
    latest = -1
    for e in lcmtypes.events(log_path):
        if e.channel != channel("V2V"):
            continue
        m = types.v2v_state_t.decode(e.data)
        auth = v2x_auth.auth_of(m)
        if m.vehicle not in cars or not auth or auth in own or auth in seen:
            continue
        seen.add(auth)
        if not episodes or m.utime < latest - NEW_EPISODE_BACK_US:
            episodes.append({})
            latest = -1
        episodes[-1][m.vehicle] = max(episodes[-1].get(m.vehicle, 0), m.seq + 1)
        latest = max(latest, m.utime)
    return episodes, len(seen)


def light_offs(log_path: Path, types: Any) -> int | None:
    """Light states showing OFF in an LCM log [count]: the intersection's lights run their
    programs (GREEN, YELLOW, RED), so every OFF is a forged command obeyed. None when the log
    holds no light state at all (nothing was watched: the figure is missing, not 0)."""
    states = [
        types.traffic_light_state_t.decode(e.data).state
        for e in lcmtypes.events(log_path)
        if e.channel == channel("TRAFFIC_LIGHT_STATE")
    ]
    if not states:
        return None
    log(f"{len(states)} light states in the bus log")
    return sum(1 for st in states if st == types.traffic_light_state_t.OFF)


def intersection_figures(
    out: Path, key_dir: Path, originals: list[dict[str, int]], light_off_states: int | None
) -> dict[str, Any]:
    """The MARL nodes' own figures of an intersection run (out: the demo's folder): the ghosts'
    charges in their per-peer accounts (any peer that is not a real car under its own
    certificate of this run's CA; REVOKED_CAR's states accepted apart), real cars' states
    accepted beyond the states they sent (replays that got in; originals: per episode, per car,
    from the bus log's seq numbers, v2v_originals), and their V2V refusals by reason. A node without its summary, or
    an episode count that does not match the attacker's, leaves the figures missing: failed."""
    real = {
        f"NIGEL{i}": v2x_ca.load_identity(f"NIGEL{i}", key_dir).cert.serial
        for i in range(1, INTER_CARS + 1)
    }
    revoked_serials = {v2x_ca.load_identity(REVOKED_CAR, key_dir).cert.serial}
    missing: dict[str, Any] = {
        "intersection_ghost_extra_stop_s": None,
        "intersection_ghost_in_peer_table_s": None,
        "intersection_replayed_v2v_accepted": None,
        "intersection_revoked_accepted": None,
    }
    episodes = sorted(out.glob("episode-*"))
    try:
        if len(episodes) != len(originals):
            raise peer_account.AccountError(
                f"{out}: {len(episodes)} episode folders, the bus log holds {len(originals)} "
                "simulators' cars"
            )
        records: list[peer_account.PeerRecord] = []
        refused: dict[str, int] = {}
        replayed = 0
        for ep_dir, ep_originals in zip(episodes, originals):
            logs = sorted(ep_dir.glob("marl*.log"))
            if len(logs) != INTER_CARS:
                raise peer_account.AccountError(f"{ep_dir}: {len(logs)} marl logs, not 4")
            for lg in logs:
                recs, why = peer_account.read_marl(lg)
                records += recs
                replayed += peer_account.replays_accepted(recs, real, ep_originals)
                for k, v in why.items():
                    refused[k] = refused.get(k, 0) + v
    except peer_account.AccountError as e:
        log(f"no intersection account figures: {e}")
        return missing
    fake = peer_account.ghosts(records, real)
    held = sum(r.held_s for r in fake)
    in_table = sum(r.in_table_s for r in fake)
    revoked = sum(r.accepted for r in fake if r.serial in revoked_serials and r.name == REVOKED_CAR)
    log(f"MARL peer accounts: ghosts held the cars {held:.3f} s, in a peer table {in_table:.3f} s; "
        f"{replayed} replays and {revoked} revoked-certificate states accepted; V2V refused: "
        f"{refused}")  # fmt: skip
    return {
        "intersection_ghost_extra_stop_s": round(held, 3),
        "intersection_ghost_in_peer_table_s": round(in_table, 3),
        "intersection_ghost_v2v_accepted": sum(r.accepted for r in fake),
        "intersection_replayed_v2v_accepted": replayed,
        "intersection_revoked_accepted": revoked,
        "intersection_real_v2v_originals": sum(sum(ep.values()) for ep in originals),
        "intersection_marl_v2v_refused": {k: v for k, v in sorted(refused.items()) if v},
        "intersection_held_by_real_peers_s": round(
            sum(r.held_s for r in records if r not in fake), 2
        ),
        "intersection_forged_light_state_changes": light_off_states,
    }


def sim_light_drops(out: Path) -> dict[str, int]:
    """The simulators' TRAFFIC_LIGHT_COMMAND refusals by reason as their logs show them (at
    most REFUSAL_LOG_LINES lines per 10 s of sim time each: a sample, not every drop)."""
    counts: dict[str, int] = {}
    for f in sorted(out.glob("episode-*/sim.log")):
        for ln in f.read_text(errors="replace").splitlines():
            if "TRAFFIC_LIGHT_COMMAND dropped at" in ln:
                why = ln.rsplit("): ", 1)[-1]
                counts[why] = counts.get(why, 0) + 1
    return counts


def intersection_attacks(build: Path, types: Any, key_dir: Path, tmp: Path) -> dict[str, Any]:
    """One real intersection run (tools/demo --mission intersection, the real Eye, autodrive-marl
    with its shield) under IntersectionAttacker, lcm-logger keeping its light states."""
    out = tmp / "intersection"
    out.mkdir()
    ca = v2x_ca.Authority(key_dir)
    ca.issue(REVOKED_SCM, "scm", 1)
    ca.revoke([REVOKED_CAR, REVOKED_SCM])
    revoked_at = time.monotonic()
    log(f"revoked {REVOKED_CAR} (car) and {REVOKED_SCM} (scm); intersection run: "
        f"{INTER_EPISODES} episodes, seed {CITY_SEED}, --eye {CITY_EYE}")  # fmt: skip
    bus_log = tmp / "intersection-v2v-lights.lcmlog"  # V2V and the light states
    chans = f"--channel=({channel('V2V')}|{channel('TRAFFIC_LIGHT_STATE')})"
    logger = subprocess.Popen(
        lcmtypes.logger_argv(INTER_URL, "-f", "-q", chans, str(bus_log)),
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
    )  # fmt: skip
    attacker = IntersectionAttacker(types, key_dir, tmp / "rogue-ca-intersection", revoked_at)
    cmd = [sys.executable, "-m", "autodrive.hil.demo", "--mission", "intersection", "--headless",
           "--build", str(build), "--out", str(out), "--seed", str(CITY_SEED),
           "--episodes", str(INTER_EPISODES), "--timeout", str(INTER_TIMEOUT_S),
           "--lcm-url", INTER_URL, "--eye", CITY_EYE]  # fmt: skip
    try:
        subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                       timeout=INTER_TIMEOUT_S + 300)  # fmt: skip
    finally:
        attacker.close()
        logger.terminate()
        _, logger_err = logger.communicate(timeout=30)
    if not bus_log.exists():
        log(f"lcm-logger wrote no log (the V2V originals and light states unknown): {logger_err}")
    try:
        report: dict[str, Any] = json.loads((out / "report.json").read_text())
    except (OSError, ValueError) as e:
        log(f"the intersection run wrote no report: {e}")
        report = {}
    offs = light_offs(bus_log, types) if bus_log.exists() else None
    originals, logged = (
        v2v_originals(bus_log, types, attacker.cars, attacker.own_v2v)
        if offs is not None
        else ([], 0)
    )
    sent = sum(sum(ep.values()) for ep in originals)
    log(f"the real cars sent {sent} V2V states (their seq), the bus log holds {logged}")
    log(f"intersection: {report.get('episodes')} of {INTER_EPISODES} episodes, "
        f"{report.get('successes')} succeeded, {report.get('collisions')} with a collision; "
        f"pose source {report.get('pose_source')}; hostile messages {attacker.sent}; "
        f"OFF light states {offs}")  # fmt: skip
    not_run = report.get("episodes_not_run")
    return {
        **intersection_figures(out, key_dir, originals, offs),
        "intersection_seed": CITY_SEED,
        "intersection_pose_source": report.get("pose_source"),
        "intersection_real_eye": report.get("pose_source") == "eye",
        "intersection_eye_sync_give_ups": give_ups([report]) if report else None,
        "intersection_episodes": report.get("episodes"),
        "intersection_episodes_not_run": not_run,
        "intersection_successes": report.get("successes"),
        "intersection_collisions": report.get("collisions"),
        "intersection_shield_interventions": report.get("shield_interventions"),
        "intersection_hostile_messages": dict(sorted(attacker.sent.items())),
        "intersection_v2v_originals_logged": logged,
        "intersection_sim_light_drops_logged": sim_light_drops(out),
        "intersection_wall_s": report.get("wall_s"),
    }


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="tools/bench v2x", description=__doc__.split("\n")[0])
    p.add_argument("--skip-web", action="store_true", help="no login brute force (goal fails)")
    p.add_argument("--skip-city", action="store_true", help="no smart-city runs (goals fail)")
    p.add_argument(
        "--skip-intersection", action="store_true", help="no intersection run (goals fail)"
    )
    a = p.parse_args(argv)
    build = build_dir("v2x")
    types = lcmtypes.load(build)
    fig: dict[str, Any] = {}
    with tempfile.TemporaryDirectory(prefix="bench-v2x-") as tmp:
        key_dir = Path(tmp) / "keys"
        os.environ["AUTODRIVE_KEY_DIR"] = str(key_dir)  # this run's own CA, for its children too
        v2x_ca.ensure_testbed([f"NIGEL{i}" for i in range(1, CARS + 1)], key_dir)
        clib = CLib(build, key_dir)
        fig.update(crypto_and_replay(types, clib))
        fig.update(light_attacks(build, types, key_dir))
        if not a.skip_web:
            fig.update(brute_force(build, Path(tmp)))
        if not a.skip_city:
            fig.update(smart_city_attacks(build, types, key_dir, Path(tmp)))
        if not a.skip_intersection:
            fig.update(intersection_attacks(build, types, key_dir, Path(tmp)))
    fig["load_1min"] = round(os.getloadavg()[0], 1)
    ran = seeds.span(CITY_SEED, 1) if not (a.skip_city and a.skip_intersection) else UNSEEDED
    print_figures(judge(fig, GOALS, ran), key_value_lines=True)
    return 0
