"""The smart city's own driver on an imported map, in HIL: autodrive-sim on the imported MJCF in
lockstep with the unchanged autodrive-runtime on its ptys (its EKF fed by the Eye stand-in,
autodrive.hil.city.eye_standin), the advisory stand-in (autodrive.hil.city.advisory on the
imported sidecar: the lights' states as the simulator publishes them) and autodrive-city-driver
on one of the map's routes, all on real LCM. The lights run their imported programs unless a
caller commands them (signed as the SCM signs). Everything is judged on sim time from the
simulator's ground truth and light states (autodrive.hil.city.scoring: red lights, stop signs,
collisions); wall time is only a hang backstop."""

from __future__ import annotations

import math
import os
import select
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

from autodrive.core import lcmtypes, v2x_auth, v2x_ca
from autodrive.core.channels import channel
from autodrive.core.proc import ProcessGroup, wait_for_path
from autodrive.hil.city import hil, scoring

STALL_WALL_S = 120.0  # a hang backstop, not a deadline: no sim time at all for this long
STILL_M = 0.003  # a standing car's body moves less than this [m]
END_MARGIN_M = 0.15  # a route is driven once base_link is this close to its end [m]
MAX_BATCH = 500  # LCM messages handled between two looks at the run's state
SPEED_FLOOR_M_S = 0.05  # a route is given its length at this speed, plus the lights' cycle [s]


def _nearest(poly: list[tuple[float, float]], x: float, y: float) -> tuple[float, float]:
    """(distance along poly [m], distance from it [m]) of the point nearest to (x, y). Its last
    segment goes on beyond the end: a car that rolled past the end before the truth was read
    (a loaded machine) is measured across the line there, not by its distance from the end."""
    best, best_s, s = math.inf, 0.0, 0.0
    last = max((k for k, (a, b) in enumerate(zip(poly, poly[1:])) if a != b), default=-1)
    for k, ((ax, ay), (bx, by)) in enumerate(zip(poly, poly[1:])):
        dx, dy = bx - ax, by - ay
        seg = math.hypot(dx, dy)
        hi = math.inf if k == last else 1.0
        u = 0.0 if seg == 0 else max(0.0, min(hi, ((x - ax) * dx + (y - ay) * dy) / seg**2))
        d = math.hypot(ax + u * dx - x, ay + u * dy - y)
        if d < best:
            best, best_s = d, s + u * seg
        s += seg
    return best_s, best


def start_before(
    doc: dict[str, Any], lane: str, point: tuple[float, float], back_m: float
) -> tuple[float, float, float]:
    """The pose (x, y, yaw) [m, m, rad] on lane's centre line back_m before its point nearest to
    point."""
    pts = next(ln["centre_line"] for ln in doc["lanes"] if ln["name"] == lane)
    k = min(range(len(pts)), key=lambda i: math.dist((pts[i]["x_m"], pts[i]["y_m"]), point))
    left = back_m
    while k > 0:
        a, b = pts[k - 1], pts[k]
        seg = math.dist((a["x_m"], a["y_m"]), (b["x_m"], b["y_m"]))
        if seg >= left:
            u = 1.0 - left / seg
            return (a["x_m"] + u * (b["x_m"] - a["x_m"]), a["y_m"] + u * (b["y_m"] - a["y_m"]),
                    math.atan2(b["y_m"] - a["y_m"], b["x_m"] - a["x_m"]))  # fmt: skip
        left -= seg
        k -= 1
    raise ValueError(f"lane {lane} is shorter than {back_m} m before {point}")


class CityStack:
    """The processes of one car on an imported map (sidecar NAME.json beside NAME.xml), its
    bus and what it saw: truth (t, x, y, yaw, v, collisions) and lights (id -> state)."""

    def __init__(self, sidecar: Path, route: str, build: Path, url: str, out: Path,
                 log: Callable[[str], None], sim_limit_s: float) -> None:  # fmt: skip
        self.sidecar, self.route, self.build, self.url, self.out = sidecar, route, build, url, out
        self.log, self.sim_limit_s = log, sim_limit_s
        self.types = lcmtypes.load(build)
        self.procs = ProcessGroup(log)
        self.truth: dict[str, float] = {}
        self.lights: dict[int, int] = {}
        self.scorer = scoring.Scorer(scoring.MapFacts.load(sidecar))
        self.lc: Any = None

    def start(self, start: tuple[float, float, float]) -> None:
        """The simulator (car 1 at start), the runtime, the Eye and advisory stand-ins; not the
        driver (start_driver)."""
        out, run_dir = self.out, self.out / "run"
        run_dir.mkdir(parents=True, exist_ok=True)
        os.environ["AUTODRIVE_KEY_DIR"] = str(out / "keys")
        v2x_ca.ensure_run_keys(["NIGEL1"], self.log)  # and the V2I certificates
        self.signer = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM"))
        self.bus_clock = v2x_auth.BusClock()
        self.lc = lcmtypes.bus(self.url)
        self.lc.subscribe(channel("GROUND_TRUTH", "NIGEL1"), self._on_truth)
        self.lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), self._on_light)
        build, url = self.build, self.url
        xml = self.sidecar.with_suffix(".xml")
        sim = [build / "bin" / "autodrive-sim", "--map", xml, "--cars", "1"]
        sim += ["--start", f"{start[0]:.4f},{start[1]:.4f},{math.degrees(start[2]):.3f}"]
        sim += ["--lockstep-client", "--run-dir", run_dir, "--lcm-url", url]
        sim += ["--duration", self.sim_limit_s + 20]
        self.procs.start("autodrive-sim", sim, out / "sim.log")
        wait_for_path(run_dir / "nigel1-nano", 60, self.procs)
        pose0 = hil.start_poses(build, url, 1)[0]
        cfg = hil.runtime_config(out, run_dir, url, 1, pose0, self.route, lidar=True)
        self.procs.start("runtime", [build / "bin" / "autodrive-runtime", "--config", cfg],
                         out / "runtime.log")  # fmt: skip
        py = sys.executable
        self.procs.start("eye-standin", [py, "-m", "autodrive.hil.city.eye_standin", "--vehicles",
                         "NIGEL1", "--lcm-url", url, "--build", build], out / "eye.log")  # fmt: skip
        self.procs.start("advisory", [py, "-m", "autodrive.hil.city.advisory", "--map",
                         self.sidecar, "--vehicles", "NIGEL1", "--routes", self.route,
                         "--lcm-url", url, "--build", build], out / "advisory.log")  # fmt: skip

    def start_driver(self) -> None:
        drv = [self.build / "bin" / "autodrive-city-driver", "--map", self.sidecar, "--route",
               self.route, "--lcm-url", self.url, "--clock", "sim"]  # fmt: skip
        self.procs.start("city-driver", drv, self.out / "driver.log")

    def stop(self) -> None:
        self.procs.stop_all()

    def _on_truth(self, _ch: str, data: bytes) -> None:
        m = self.types.ground_truth_t.decode(data)
        t = m.utime * 1e-6
        self.truth.update(t=t, x=m.position_m[0], y=m.position_m[1], yaw=m.yaw_rad,
                          v=m.linear_velocity_m_s[0])  # fmt: skip
        self.scorer.truth("NIGEL1", t, m.position_m[0], m.position_m[1], m.yaw_rad,
                          bool(m.in_collision))  # fmt: skip
        self.bus_clock.heard(m.utime)  # the sim's time: commands are signed on it

    def _on_light(self, _ch: str, data: bytes) -> None:
        m = self.types.traffic_light_state_t.decode(data)
        self.lights[m.light_id] = m.state
        self.scorer.light(m.light_id, m.state)
        self.bus_clock.heard(m.utime)

    def command(self, light_id: int, state: int) -> None:
        """A light command as the SCM sends it: signed, on the bus's (the sim's) clock, held."""
        c = self.types.traffic_light_command_t()
        c.utime, c.light_id, c.state, c.duration_s = self.bus_clock.now_us(), light_id, state, 0.0
        self.signer.sign(channel("TRAFFIC_LIGHT_COMMAND"), c, self.bus_clock.now_us())
        self.lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), c.encode())

    def wait_for(self, what: str, cond: Callable[[], bool], sim_s: float = 30.0) -> None:
        """Until cond holds, within sim_s of sim time (AssertionError else)."""
        t0, seen_t, seen_wall = self.truth.get("t", 0.0), None, time.monotonic()
        while True:
            self.procs.check()
            for _ in range(MAX_BATCH):  # all that waits, so that truth is the sim's latest
                if not select.select([self.lc.fileno()], [], [], 0.05 if _ == 0 else 0.0)[0]:
                    break
                self.lc.handle()
            now = self.truth.get("t")
            if now != seen_t:
                seen_t, seen_wall = now, time.monotonic()
            elif time.monotonic() - seen_wall > STALL_WALL_S:
                raise AssertionError(
                    f"{what}: the sim clock stopped for {STALL_WALL_S} s; {self.truth}"
                )
            if self.truth and cond():
                return
            t = self.truth.get("t", 0.0)
            if self.truth and (t > t0 + sim_s or t > self.sim_limit_s):
                raise AssertionError(f"{what}: not within {sim_s} s of sim time; {self.truth}")

    def hold(self, light_id: int, state: int, what: str) -> None:
        """Commands the light until it shows state (a command may come before the sim listens)."""
        sent = [-1.0]

        def shown() -> bool:
            if self.lights.get(light_id) != state and (
                sent[0] < 0 or self.truth["t"] - sent[0] > 0.5
            ):
                self.command(light_id, state)
                sent[0] = self.truth["t"]
            return self.lights.get(light_id) == state

        self.wait_for(what, shown)

    def stood_at(self, line: scoring.StopPoint, hold_s: float) -> Callable[[], bool]:
        """A condition: the car has stood within 0.25 m before line (front at most 0.1 m past
        it) for hold_s of sim time, judged by where it is (its body's speed wobbles)."""
        anchor: list[tuple[float, float, float] | None] = [None]

        def stood() -> bool:
            tr = self.truth
            past = scoring.front_past_m(tr["x"], tr["y"], tr["yaw"], line)
            if not -0.25 < past < 0.1:
                anchor[0] = None
            elif anchor[0] is None or math.dist(anchor[0][1:], (tr["x"], tr["y"])) > STILL_M:
                anchor[0] = (tr["t"], tr["x"], tr["y"])
            return anchor[0] is not None and tr["t"] - anchor[0][0] >= hold_s

        return stood


@dataclass(frozen=True)
class RouteDrive:
    route: str
    ok: bool  # reached the end within the lane, no violation, no collision
    reached_end: bool
    max_lateral_m: float  # base_link's largest distance from the route's centre line
    half_width_m: float
    max_lateral_at: tuple[float, float]  # where along the route [m] and when [s, sim] it was
    red_light_violations: int
    stop_sign_violations: int
    collisions: int
    stops_at_red: int  # the car stood at a red light and went on after it turned
    sim_s: float


def drive_route(sidecar: Path, route: dict[str, Any], build: Path, url: str, out: Path,
                log: Callable[[str], None], cycle_s: float) -> RouteDrive:  # fmt: skip
    """Drives the sidecar's route (its record) from its start to its end with the city driver,
    the lights on their programs; at most its length at SPEED_FLOOR_M_S plus two light cycles of
    sim time."""
    poly = [(float(p[0]), float(p[1])) for p in route["polyline_m"]]
    (x0, y0), (x1, y1) = poly[0], poly[1]
    length = float(route["length_m"])
    limit_s = length / SPEED_FLOOR_M_S + 2 * cycle_s
    stack = CityStack(sidecar, route["name"], build, url, out, log, limit_s)
    worst = [0.0, 0.0, 0.0]  # distance, along, sim time

    def at_end() -> bool:
        tr = stack.truth
        s, d = _nearest(poly, tr["x"], tr["y"])
        if d > worst[0]:
            worst[:] = [d, s, tr["t"]]
        return s >= length - END_MARGIN_M

    reached = False
    try:
        stack.start((x0, y0, math.atan2(y1 - y0, x1 - x0)))
        stack.wait_for("the sim's first truth", lambda: True, 30.0)
        stack.start_driver()
        try:
            stack.wait_for(f"{route['name']} driven to its end", at_end, limit_s)
            reached = True
        except AssertionError as err:
            log(f"{route['name']}: {err}")
    finally:
        stack.stop()
    rep = stack.scorer.report()
    red, sign, hits = (rep["red_light_violations"], rep["stop_sign_violations"],
                       rep["collisions"])  # fmt: skip
    ok = reached and worst[0] <= route["half_width_m"] and red == sign == hits == 0
    return RouteDrive(route["name"], ok, reached, worst[0], route["half_width_m"],
                      (round(worst[1], 3), round(worst[2], 2)), red, sign, hits,
                      rep["stop_line_crossings"]["after_red_stop"], stack.truth.get("t", 0.0))  # fmt: skip
