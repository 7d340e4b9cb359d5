"""The Smart City Manager's core: it keeps each car's latest pose, the lights' controller and
the event log, talks LCM (poses, V2V routes and TRAFFIC_LIGHT_STATE in, each signed; TRAFFIC_LIGHT_COMMAND
and each car's V2I advisory out) and writes everything through one database writer.

Threads: LCM receive, the control loop (lights at 20 Hz, advisories at 10 Hz per car) and the
writer. The web API (api.py) calls the methods below; one lock guards the shared state.

Its clock (--clock wall|sim, autodrive.core.clock.Clock) times the lights, the advisories' rate
and every freshness (poses, the Eye's preference, light states). With --clock sim that is
SIM_CLOCK, so a simulated town paced at 0.1x real time is served as one at full speed; a frozen
SIM_CLOCK (still for clock.FROZEN_AFTER_S of wall time) makes every car stale (no advisory:
the cars' drivers then see every light red) and every light unknown."""

from __future__ import annotations

import collections
import json
import math
import queue
import re
import select
import threading
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from sqlalchemy import Engine, select as sql_select

from autodrive.core import channels, lcmtypes, v2x_auth, v2x_ca
from autodrive.core.clock import MODES as clock_modes
from autodrive.core.clock import Clock
from autodrive.core.v2x_cert import CertificateError
from autodrive.maps import MapDescription
from autodrive.scm.core.db import sessions
from autodrive.scm.lights import STATES, Change, ControlError, Controller, Light, Program
from autodrive.scm.models import Light as LightRow
from autodrive.scm.models import Sign as SignRow
from autodrive.scm.receiver import Receiver
from autodrive.scm.roadnet import Ahead, Place, for_map
from autodrive.scm.store import Writer

STALE_S = 0.5  # a car's pose older than this [s, clock] gets no advisory (the car goes stale)
EYE_PREFERRED_S = 0.5  # an Eye pose this recent [s, clock] wins over the EKF's
QUEUE_M = 1.2  # a car this close to a red light's stop line [m] is queued on its approach
COMMAND_HOLD_S = 2.0  # each light command holds this long [s]; refreshed every REFRESH_S
REFRESH_S = 0.5
# The simulator publishes every light at 10 Hz of sim time and each change at once; a light
# not heard of for this long [s, clock] is unknown (with --clock sim, a frozen simulator too).
LIGHT_UNKNOWN_S = 5.0
VEHICLE_PATTERN = "[A-Z][A-Z0-9]*"  # a vehicle name: capitals and digits
CLOCKS = clock_modes  # the SCM's clock: this machine's, or the simulator's SIM_CLOCK


def now_us() -> int:
    return int(time.time() * 1e6)


@dataclass
class Car:
    name: str
    x_m: float = 0.0
    y_m: float = 0.0
    yaw_rad: float = 0.0
    speed_m_s: float = 0.0
    source: str = ""
    utime: int = 0  # the pose's stamp [us]
    seen_s: float = 0.0  # wall time of the last pose [s] (shown, stored)
    seen_c: float | None = None  # the last pose's arrival [s, the SCM's clock] (its freshness)
    eye_seen_c: float | None = None  # the last Eye pose's arrival [s, the SCM's clock]
    kept_utime: int = -(10**18)  # stamp of the last pose kept in the history [us]
    route: str = ""
    place: Place | None = None
    ahead: Ahead = field(default_factory=Ahead)
    seq: int = 0
    status: str = "unseen"


class Scm:
    def __init__(
        self,
        m: MapDescription,
        engine: Engine,
        build: Path,
        lcm_url: str,
        vehicles: list[str],
        history_hz: float = 10.0,
        advisory_hz: float = 10.0,
        clock: str = "wall",
        identity: str = "SCM",
    ) -> None:
        if clock not in CLOCKS:
            raise ValueError(f"clock must be one of {CLOCKS}, got {clock!r}")
        self.map = m
        self.clock = clock
        self.time = Clock(clock)  # the lights', the advisories' and the freshness' clock
        self.engine = engine
        self.sessions = sessions(engine)
        self.types = lcmtypes.load(build)
        self.lcm_url = lcm_url
        self.vehicles = vehicles
        self.history_us = 0 if history_hz <= 0 else int(0.9e6 / history_hz)
        self.advisory_period_s = 1.0 / advisory_hz
        self.roadnet = for_map(m, build)
        self.lock = threading.RLock()
        self.cars: dict[str, Car] = {v: Car(v) for v in vehicles}
        # id -> state, time left [s], seen [s, wall], seen [s, clock]
        self.sim_states: dict[int, tuple[str, float, float, float | None]] = {}
        self.recent: collections.deque[dict[str, Any]] = collections.deque(maxlen=200)
        self._event_seq = 0
        self.stats = {
            "poses_in": 0,
            "advisories_out": 0,
            "commands_out": 0,
            "bad_messages": 0,
            "refused_messages": 0,  # signed channels whose envelope did not check out
        }
        self.controller = self._make_controller()
        self.writer = Writer(self.sessions)
        self._stop = threading.Event()
        self.receiver = Receiver(build, lcm_url, VEHICLE_PATTERN)
        self._threads: list[threading.Thread] = []
        self.lc = lcmtypes.bus(lcm_url)
        self.lc_out = lcmtypes.bus(lcm_url)  # publishing from the control thread
        self.lcm_lock = threading.Lock()
        # V2I advisories and light commands go out signed with the SCM's certificate
        # (tools/keys issue --role scm); CertificateError naming the file when it is missing.
        self.signer = v2x_auth.MessageSigner(v2x_ca.load_identity(identity))
        # Light states count only when signed by a light controller (the simulator in HIL);
        # what the SCM signs and checks is stamped with the bus's clock (sim time in HIL).
        self.verifier = v2x_auth.Verifier()
        self.bus_clock = v2x_auth.BusClock()
        self.drop_log = v2x_auth.DropLog()
        self._crl_checked_s = 0.0

    # --- set-up -------------------------------------------------------------------------------

    def _make_controller(self) -> Controller:
        tile_of = {s.name: t.spec.name for t in self.map.tile_contents() for s in t.stop_lines}
        lights = []
        with self.sessions() as s, s.begin():
            rows = {r.id: r for r in s.scalars(sql_select(LightRow))}
            for spec in self.map.lights():
                p = spec.program
                program = Program.from_map(p.cycle_s, p.offset_s, p.green_s, p.yellow_s)
                junction = tile_of.get(spec.stop_line, spec.stop_line)
                row = rows.get(spec.id)
                if row is None:
                    s.add(
                        LightRow(
                            id=spec.id,
                            junction=junction,
                            stop_line=spec.stop_line,
                            lane=spec.lane,
                            state="RED",
                            sim_state="",
                            mode="fixed",
                            program=json.dumps(program.to_json()),
                            updated_us=now_us(),
                        )
                    )
                else:  # an operator's program survives a restart
                    try:
                        program = Program.from_json(json.loads(row.program))
                    except (ValueError, ControlError):
                        row.program = json.dumps(program.to_json())
                lights.append(Light(spec.id, junction, program))
            s.query(SignRow).delete()
            for sign in self.map.placed_signs():
                limit = sign.speed_limit_m_s if sign.speed_limit_m_s is not None else -1.0
                s.add(
                    SignRow(
                        id=sign.id,
                        kind=sign.kind,
                        x_m=sign.position_m[0],
                        y_m=sign.position_m[1],
                        yaw_rad=sign.yaw_rad,
                        lane=sign.lane or "",
                        speed_limit_m_s=limit,
                    )
                )
        c = Controller(lights, self.map.light_conflicts(), self.map.kit.traffic_light.min_all_red_s)
        with self.sessions() as s:
            for row in s.scalars(sql_select(LightRow)):
                if row.junction in c.junctions and row.mode in ("fixed", "actuated", "manual"):
                    c.junctions[row.junction].mode = row.mode
        return c

    def start(self) -> None:
        self.writer.start()
        self.receiver.start()  # before the threads below: a process of its own for the poses
        self.lc.subscribe(channels.channel("TRAFFIC_LIGHT_STATE"), self._on_light_state)
        self.lc.subscribe(channels.channel("V2V"), self._on_v2v)
        # the lights' clock with --clock sim, and the bus clock of the signed messages always
        self.lc.subscribe(channels.channel("SIM_CLOCK"), self._on_sim_clock)
        self.event("server", "start", "scm", {"map": self.map.name, "vehicles": self.vehicles})
        loops = ((self._lcm_loop, "scm-lcm"), (self._ingest_loop, "scm-ingest"),
                 (self._control_loop, "scm-control"))  # fmt: skip
        for target, name in loops:
            t = threading.Thread(target=target, name=name, daemon=True)
            t.start()
            self._threads.append(t)

    def ready(self) -> bool:
        """Started and every part of it alive: the LCM, ingest and control threads, the pose
        receiver process and the database writer."""
        return (
            bool(self._threads)
            and all(t.is_alive() for t in self._threads)
            and self.receiver.proc.is_alive()
            and self.writer.alive()
            and not self._stop.is_set()
        )

    def stop(self) -> None:
        self._stop.set()
        for t in self._threads:
            t.join(timeout=5)
        self.receiver.stop()
        self.event("server", "stop", "scm", {})
        self.writer.stop()
        self.engine.dispose()  # close the pool's connections: nothing of SQLite outlives the server

    # --- LCM in -------------------------------------------------------------------------------

    def _lcm_loop(self) -> None:
        fd = self.lc.fileno()
        while not self._stop.is_set():
            if select.select([fd], [], [], 0.1)[0]:
                self.lc.handle()

    def _decode(self, kind: Any, data: bytes) -> Any:
        try:
            return kind.decode(data)
        except Exception:  # a message that does not decode is counted, never believed
            self.stats["bad_messages"] += 1
            return None

    def _ingest_loop(self) -> None:
        """Poses from the receiver process, a batch at a time."""
        while not self._stop.is_set():
            try:
                batch = self.receiver.queue.get(timeout=0.1)
            except queue.Empty:
                continue
            with self.lock:
                for source, vehicle, utime, x_m, y_m, yaw_rad, speed in batch:
                    self.pose(vehicle, utime, x_m, y_m, yaw_rad, speed, source)

    def _on_v2v(self, _chan: str, data: bytes) -> None:
        msg = self._decode(self.types.v2v_state_t, data)
        if msg is None or not re.fullmatch(VEHICLE_PATTERN, msg.vehicle):
            return
        # A car's route only from that car's certificate: a ghost (or a real car under another's
        # name) would move a real car onto another route and its advisories to another light.
        if not self._verified(_chan, msg, "V2V", msg.vehicle):
            return
        with self.lock:
            car = self.cars.setdefault(msg.vehicle, Car(msg.vehicle))
            if msg.route != car.route and (msg.route == "" or msg.route in self.roadnet.routes):
                car.route = msg.route
                self.writer.vehicle(car.name, {"route": car.route})

    def _on_sim_clock(self, _chan: str, data: bytes) -> None:
        msg = self._decode(self.types.sim_clock_t, data)
        if msg is not None:  # forward only: a late message never turns the clock back
            self.time.on_sim_clock(msg.utime)
            self.bus_clock.heard(msg.utime)

    def city_now(self) -> float | None:
        """The lights' clock [s]: wall time, or with clock 'sim' the simulator's SIM_CLOCK, so
        that yellow, all-red and the programs last what they should in the simulated world
        however fast or slowly the simulator runs (in lockstep on a loaded machine it may run at
        half real time, or several times faster on a quiet one); None before the first
        SIM_CLOCK (the lights are then neither commanded nor timed)."""
        return self.time.now_s()

    def _on_light_state(self, chan: str, data: bytes) -> None:
        msg = self._decode(self.types.traffic_light_state_t, data)
        if msg is None or not 0 <= msg.state < len(STATES):
            return
        if not self._verified(chan, msg, "TRAFFIC_LIGHT_STATE"):
            return
        self.bus_clock.heard(v2x_auth.sender_utime(v2x_auth.auth_of(msg)) or 0)
        state, t = STATES[msg.state], time.time()
        with self.lock:
            before = self.sim_states.get(msg.light_id)
            tc = self.city_now()
            self.sim_states[msg.light_id] = (state, float(msg.time_remaining_s), t, tc)
            if tc is not None:
                self.controller.observed(msg.light_id, state, tc)
            if (before is None or before[0] != state) and msg.light_id in self.controller.lights:
                self.writer.light(msg.light_id, {"sim_state": state, "updated_us": now_us()})

    def pose(
        self,
        vehicle: str,
        utime: int,
        x_m: float,
        y_m: float,
        yaw_rad: float,
        speed_m_s: float | None,
        source: str,
        seq: int = -1,
        keep: bool = False,
    ) -> None:
        """One pose of a car (from LCM, or the REST ingest with source 'rest'); keep: into the
        history whatever the thinning (a script's poses are all kept)."""
        if not all(math.isfinite(v) for v in (x_m, y_m, yaw_rad)):
            self.stats["bad_messages"] += 1
            return
        t = time.time()
        with self.lock:
            tc = self.city_now()
            self.stats["poses_in"] += 1
            car = self.cars.get(vehicle)
            if car is None:
                car = self.cars[vehicle] = Car(vehicle)
            if source == "eye":
                car.eye_seen_c = tc
            elif source == "ekf" and self.time.fresh(car.eye_seen_c, EYE_PREFERRED_S):
                return  # the Eye is running: its poses are the ones kept
            if speed_m_s is None:  # the Eye gives no speed: from the last pose
                dt = (utime - car.utime) * 1e-6
                if car.source == source and 0 < dt < 0.5:
                    v = math.hypot(x_m - car.x_m, y_m - car.y_m) / dt
                    speed_m_s = 0.7 * car.speed_m_s + 0.3 * v
                else:
                    speed_m_s = 0.0
            car.x_m, car.y_m, car.yaw_rad, car.speed_m_s = x_m, y_m, yaw_rad, speed_m_s
            car.source, car.utime, car.seen_s, car.seen_c = source, utime, t, tc
            if car.status != "ok":
                car.status = "ok"
                self.event("server", "vehicle_ok", vehicle, {"source": source})
            keep = keep or utime - car.kept_utime >= self.history_us or utime < car.kept_utime
            if keep:
                car.kept_utime = utime
                self.writer.pose(
                    {
                        "vehicle": vehicle,
                        "utime": utime,
                        "seq": seq,
                        "x_m": x_m,
                        "y_m": y_m,
                        "yaw_rad": yaw_rad,
                        "speed_m_s": speed_m_s,
                        "source": source,
                    }
                )

    # --- control loop -------------------------------------------------------------------------

    def _control_loop(self) -> None:
        next_refresh = next_vehicles = time.monotonic()
        next_adv_c = -math.inf  # the next advisories are due at this time [s, the SCM's clock]
        refreshed_c = -math.inf  # the lights' clock at the last refresh [s]
        while not self._stop.wait(0.05):
            t = time.time()
            mono = time.monotonic()
            with self.lock:
                tc = self.city_now()
                if tc is not None and tc >= next_adv_c:  # the advisories' rate on the clock
                    next_adv_c = max(next_adv_c + self.advisory_period_s, tc)
                    self._advise(t, tc)
                if tc is not None:
                    self._apply(self.controller.tick(tc, self._demand()))
                    # each command holds COMMAND_HOLD_S on the simulator's clock: refreshed every
                    # REFRESH_S of wall time and of the lights' clock, whichever comes first
                    if mono >= next_refresh or tc - refreshed_c >= REFRESH_S:
                        next_refresh, refreshed_c = mono + REFRESH_S, tc
                        for light in self.controller.lights.values():
                            if light.known:
                                self._command(light.id, light.state)
                if mono >= next_vehicles:
                    next_vehicles = mono + 0.2
                    self._vehicle_rows(t)

    def _demand(self) -> dict[int, bool]:
        out: dict[int, bool] = {}
        for car in self.cars.values():
            a = car.ahead
            if car.status == "ok" and a.light_id >= 0 and 0 <= a.stop_line_distance_m <= QUEUE_M:
                out[a.light_id] = True
        return out

    def _apply(self, changes: list[Change]) -> None:
        for ch in changes:
            self._command(ch.light_id, ch.state)
            self.writer.light(ch.light_id, {"state": ch.state, "updated_us": now_us()})
            self.event(ch.actor, "light_state", f"light {ch.light_id}", {"state": ch.state})

    def _command(self, light_id: int, state: str) -> None:
        msg = self.types.traffic_light_command_t()
        msg.utime = now_us()
        msg.light_id, msg.state, msg.duration_s = light_id, STATES.index(state), COMMAND_HOLD_S
        self._publish_signed(channels.channel("TRAFFIC_LIGHT_COMMAND"), msg)
        self.stats["commands_out"] += 1

    def _publish_signed(self, chan: str, msg: Any) -> None:
        """Signs msg on the bus's clock (the receivers judge its freshness on theirs: in HIL
        the simulator's, which the SCM hears from SIM_CLOCK and the light states)."""
        self._publish(chan, self.signer.sign(chan, msg, self.bus_clock.now_us()).encode())

    def _verified(self, chan: str, msg: Any, channel_id: str, name: str | None = None) -> bool:
        """True when msg's envelope checks out (v2x_auth; name: the certificate's name it needs);
        else counted and logged, bounded."""
        now_s = time.time()
        if now_s - self._crl_checked_s >= 0.25:  # the revocation list (a stat), 4 times a second
            self._crl_checked_s = now_s
            try:
                self.verifier.reload()
            except (OSError, CertificateError) as err:
                self.drop_log.log(f"revocation list: {err} (the list held so far stays)", now_s)
        if channel_id == "TRAFFIC_LIGHT_STATE":  # the simulator's time is heard from them too
            claimed = v2x_auth.sender_utime(v2x_auth.auth_of(msg))
            now_us = self.bus_clock.now_us()
            if claimed is not None and self.bus_clock.sim_us is None:
                now_us = claimed  # the first one sets the clock: its counter is still checked
        else:
            now_us = self.bus_clock.now_us()
        verdict = self.verifier.verify(chan, msg, v2x_auth.roles_for(channel_id), name, now_us)
        if verdict.ok:
            return True
        self.stats["refused_messages"] += 1
        self.drop_log.log(verdict.describe(chan), now_s)
        return False

    def _publish(self, chan: str, data: bytes) -> None:
        with self.lcm_lock:
            self.lc_out.publish(chan, data)

    def light_view(self, light_id: int, t: float, tc: float | None) -> tuple[str, float]:
        """The state a car should obey and its time left [s] (< 0: not known). The light is the
        authority on what it shows: the advisory is the state the simulator (the light) last
        published on TRAFFIC_LIGHT_STATE, never the SCM's own command, which may not have
        reached it yet (a loaded machine pauses the simulator in lockstep, so its states come
        late; a GREEN announced from the command let a car drive off at a red light). The time
        left is the SCM's (it decides the next change) while the light shows the SCM's state,
        else unknown (the light is about to follow a command). No state yet, or none for
        LIGHT_UNKNOWN_S of the clock (or a frozen sim clock): unknown, advised as RED. t: wall
        time, tc: the lights' clock [s]."""
        sim = self.sim_states.get(light_id)
        if sim is None or not self.time.fresh(sim[3], LIGHT_UNKNOWN_S):
            return "RED", -1.0
        shown = sim[0]
        light = self.controller.lights[light_id]
        if shown == light.state and tc is not None:
            return shown, self.controller.time_left_s(light_id, tc)
        return shown, -1.0

    def _advise(self, t: float, tc: float | None) -> None:
        for car in self.cars.values():
            if not self.time.fresh(car.seen_c, STALE_S):
                if car.status == "ok":
                    car.status = "stale"
                    self.event(
                        "server", "vehicle_stale", car.name, {"age_s": round(t - car.seen_s, 2)}
                    )
                continue
            if self.vehicles and car.name not in self.vehicles:
                continue  # placed and advised: the listed cars only (others are only stored)
            car.place, car.ahead = self.roadnet.follow(
                car.x_m, car.y_m, car.yaw_rad, car.route, car.place
            )
            msg = self.types.v2i_advisory_t()
            stamp_s = t if tc is None else tc  # on the SCM's clock
            msg.utime, msg.seq, msg.vehicle = int(stamp_s * 1e6), car.seq, car.name
            car.seq += 1
            a = car.ahead
            msg.light_id = a.light_id
            state, left = (
                self.light_view(a.light_id, t, tc)
                if a.light_id in self.controller.lights
                else ("OFF", -1.0)
            )
            msg.light_state = STATES.index(state)
            msg.light_time_remaining_s = left
            msg.stop_line_distance_m = a.stop_line_distance_m
            msg.sign_id, msg.sign_kind, msg.sign_distance_m = (
                a.sign_id,
                a.sign_kind,
                a.sign_distance_m,
            )
            msg.speed_limit_m_s = a.speed_limit_m_s
            self._publish_signed(channels.channel("V2I", car.name), msg)
            self.stats["advisories_out"] += 1

    def _vehicle_rows(self, t: float) -> None:
        for car in self.cars.values():
            if car.seen_s > 0:
                self.writer.vehicle(
                    car.name,
                    {
                        "x_m": car.x_m,
                        "y_m": car.y_m,
                        "yaw_rad": car.yaw_rad,
                        "speed_m_s": car.speed_m_s,
                        "source": car.source,
                        "route": car.route,
                        "lane": car.place.lane if car.place else "",
                        "status": car.status,
                        "updated_us": int(car.seen_s * 1e6),
                    },
                )

    # --- what the API calls -------------------------------------------------------------------

    def event(self, actor: str, kind: str, subject: str, detail: dict[str, Any]) -> None:
        with self.lock:
            self._event_seq += 1
            row = {
                "utime": now_us(),
                "actor": actor,
                "kind": kind,
                "subject": subject,
                "detail": json.dumps(detail),
            }
            self.recent.append({"seq": self._event_seq, **row, "detail": detail})
            self.writer.event(row)

    def set_light(self, light_id: int, state: str, actor: str) -> str:
        with self.lock:
            tc = self.city_now()
            if tc is None:
                raise ControlError("the lights follow the simulator's clock: no SIM_CLOCK yet")
            what = self.controller.request(light_id, state, actor, tc)
            light = self.controller.lights[light_id]
            self.writer.light(light_id, {"mode": "manual"})
            self.event(actor, "light_request", f"light {light_id}", {"state": state, "plan": what})
            self._apply(self.controller.tick(tc, self._demand()))  # at once, not next tick
            self._mode_rows(light.junction)
            return what

    def set_mode(self, junction: str, mode: str, actor: str, max_green_s: float | None) -> None:
        with self.lock:
            self.controller.set_mode(junction, mode, max_green_s)
            self._mode_rows(junction)
            self.event(actor, "junction_mode", junction, {"mode": mode, "max_green_s": max_green_s})

    def _mode_rows(self, junction: str) -> None:
        j = self.controller.junctions[junction]
        for i in j.lights:
            self.writer.light(i, {"mode": j.mode})

    def set_program(self, light_id: int, doc: Any, actor: str) -> Program:
        with self.lock:
            program = Program.from_json(doc, f"light {light_id} program")
            self.controller.set_program(light_id, program)
            self.writer.light(light_id, {"program": json.dumps(program.to_json())})
            self.event(actor, "light_program", f"light {light_id}", program.to_json())
            return program

    def snapshot(self) -> dict[str, Any]:
        t = time.time()
        with self.lock:
            tc = self.city_now()
            cars = []
            for c in sorted(self.cars.values(), key=lambda c: c.name):
                if c.seen_s == 0 and c.name not in self.vehicles:
                    continue
                cars.append(
                    {
                        "name": c.name,
                        "x_m": c.x_m,
                        "y_m": c.y_m,
                        "yaw_rad": c.yaw_rad,
                        "speed_m_s": c.speed_m_s,
                        "source": c.source,
                        "status": c.status,
                        "age_s": round(t - c.seen_s, 3) if c.seen_s else None,
                        "route": c.route,
                        "lane": c.place.lane if c.place else "",
                        "next_light": c.ahead.light_id,
                        "stop_line_m": c.ahead.stop_line_distance_m,
                        "next_sign": c.ahead.sign_kind,
                        "speed_limit_m_s": c.ahead.speed_limit_m_s,
                    }
                )
            lights = []
            for light in sorted(self.controller.lights.values(), key=lambda x: x.id):
                sim = self.sim_states.get(light.id)
                lights.append(
                    {
                        "id": light.id,
                        "junction": light.junction,
                        "state": light.state,
                        "target": light.target,
                        "sim_state": sim[0] if sim and t - sim[2] < 2.0 else "",
                        "mode": self.controller.junctions[light.junction].mode,
                        "time_left_s": (
                            round(self.controller.time_left_s(light.id, tc), 2)
                            if tc is not None
                            else -1.0
                        ),
                        "program": light.program.to_json(),
                    }
                )
            junctions = [
                {"name": j.name, "mode": j.mode, "max_green_s": j.max_green_s, "lights": j.lights}
                for j in self.controller.junctions.values()
            ]
            return {
                "utime": int(t * 1e6),
                "vehicles": cars,
                "lights": lights,
                "junctions": junctions,
                "events": list(self.recent)[-30:],
                "stats": {
                    **self.stats,
                    "lcm_poses_received": int(self.receiver.counters[0]),
                    "lcm_poses_undecodable": int(self.receiver.counters[1]),
                    "lcm_eye_poses_refused": int(self.receiver.counters[2]),
                    "db_rows_written": self.writer.rows_written,
                    "db_errors": self.writer.errors,
                    "db_pending": self.writer.pending,
                    "db_last_error": self.writer.last_error,
                },
            }
