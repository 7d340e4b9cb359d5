"""Traffic-light control: programs, the three modes and the interlock every change goes through.

Modes are per junction (the lights of one intersection tile): `fixed` runs each light's program
(offset and phases), `actuated` gives green to one compatible set of lights at a time and holds
it while cars queue on its approaches (up to max_green_s), `manual` holds what the operator set.
Whatever a mode or an operator asks, the interlock enforces: GREEN -> YELLOW (the light's yellow
time) -> RED; a light turns GREEN only when every conflicting light has been RED (or OFF) for
min_all_red_s; a request to turn a light green while a conflicting light is (or is going) green
is refused with ConflictError naming that light. Pure logic: time is passed in [s]."""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from typing import Any

STATES = ("OFF", "RED", "YELLOW", "GREEN")  # index = traffic_light_state_t constant
MODES = ("fixed", "actuated", "manual")
DEFAULT_YELLOW_S = 2.0


class ControlError(ValueError):
    """A request the controller refuses; the message says which input and why."""


class ConflictError(ControlError):
    """A green that would meet a conflicting green."""


def non_red(state: str) -> bool:
    return state in ("GREEN", "YELLOW")


@dataclass(frozen=True)
class Phase:
    state: str
    duration_s: float


@dataclass(frozen=True)
class Program:
    """A light's fixed-time program: phases repeated from offset_s (on the server's clock)."""

    offset_s: float
    phases: tuple[Phase, ...]

    @property
    def cycle_s(self) -> float:
        return sum(p.duration_s for p in self.phases)

    @property
    def yellow_s(self) -> float:
        ys = [p.duration_s for p in self.phases if p.state == "YELLOW"]
        return ys[0] if ys else DEFAULT_YELLOW_S

    @property
    def green_s(self) -> float:
        return sum(p.duration_s for p in self.phases if p.state == "GREEN")

    def state_at(self, t_s: float) -> tuple[str, float]:
        """The program's state at t_s and the time left in it [s]."""
        u = (t_s - self.offset_s) % self.cycle_s
        for p in self.phases:
            if u < p.duration_s:
                return p.state, p.duration_s - u
            u -= p.duration_s
        return self.phases[-1].state, 0.0  # pragma: no cover (rounding at the cycle's end)

    def to_json(self) -> dict[str, Any]:
        return {
            "offset_s": self.offset_s,
            "phases": [{"state": p.state, "duration_s": p.duration_s} for p in self.phases],
        }

    @staticmethod
    def from_json(doc: Any, what: str = "program") -> "Program":
        """Checks a program document; ControlError names the field and the problem."""
        if not isinstance(doc, dict):
            raise ControlError(f"{what}: expected an object with offset_s and phases")
        unknown = set(doc) - {"offset_s", "phases"}
        if unknown:
            raise ControlError(f"{what}: unknown field(s) {sorted(unknown)}")
        offset = doc.get("offset_s", 0.0)
        if not isinstance(offset, (int, float)) or isinstance(offset, bool):
            raise ControlError(f"{what}.offset_s: expected a number [s], got {offset!r}")
        phases = doc.get("phases")
        if not isinstance(phases, list) or not phases:
            raise ControlError(f"{what}.phases: expected a non-empty list of phases")
        out = []
        for i, p in enumerate(phases):
            where = f"{what}.phases[{i}]"
            if not isinstance(p, dict) or set(p) != {"state", "duration_s"}:
                raise ControlError(f"{where}: expected {{state, duration_s}}, got {p!r}")
            if p["state"] not in ("RED", "YELLOW", "GREEN"):
                raise ControlError(
                    f"{where}.state: expected RED, YELLOW or GREEN, got {p['state']!r}"
                )
            d = p["duration_s"]
            if not isinstance(d, (int, float)) or isinstance(d, bool) or not 0.5 <= d <= 600:
                raise ControlError(f"{where}.duration_s: expected 0.5..600 [s], got {d!r}")
            out.append(Phase(p["state"], float(d)))
        for i, p in enumerate(out):
            nxt = out[(i + 1) % len(out)]
            if p.state == "GREEN" and nxt.state not in ("GREEN", "YELLOW"):
                raise ControlError(f"{what}.phases[{i}]: GREEN must be followed by YELLOW")
            if p.state == "YELLOW" and nxt.state not in ("YELLOW", "RED"):
                raise ControlError(f"{what}.phases[{i}]: YELLOW must be followed by RED")
        return Program(float(offset), tuple(out))

    @staticmethod
    def from_map(cycle_s: float, offset_s: float, green_s: float, yellow_s: float) -> "Program":
        red = cycle_s - green_s - yellow_s
        return Program(
            offset_s,
            (Phase("GREEN", green_s), Phase("YELLOW", yellow_s), Phase("RED", red)),
        )


@dataclass
class Light:
    id: int
    junction: str
    program: Program
    state: str = "RED"
    since_s: float = 0.0  # when the present state began [s]
    target: str = "RED"  # what the mode or operator wants; the interlock gets there
    known: bool = False  # the state has been read from the simulator (or assumed at start)


@dataclass
class Junction:
    name: str
    lights: list[int]
    mode: str = "fixed"
    sets: list[list[int]] = field(default_factory=list)  # actuated: compatible sets
    active: int = 0  # actuated: the set that has (or is getting) green
    green_since_s: float = -1.0  # when the active set turned green, <0 while it has not
    max_green_s: float = 20.0


@dataclass(frozen=True)
class Change:
    light_id: int
    state: str
    actor: str


class Controller:
    def __init__(
        self,
        lights: list[Light],
        conflicts: list[tuple[int, int]],
        min_all_red_s: float,
        start_grace_s: float = 1.0,
    ) -> None:
        self.lights = {light.id: light for light in lights}
        self.conflicts = {frozenset(c) for c in conflicts}
        self.min_all_red_s = min_all_red_s
        self.start_grace_s = start_grace_s
        self.started_s: float | None = None
        self.junctions: dict[str, Junction] = {}
        for light in lights:
            self.junctions.setdefault(light.junction, Junction(light.junction, [])).lights.append(
                light.id
            )
        for j in self.junctions.values():
            j.sets = self._compatible_sets(sorted(j.lights))
        self.actors: dict[int, str] = {}  # who asked for each light's target

    def _compatible_sets(self, ids: list[int]) -> list[list[int]]:
        sets: list[list[int]] = []
        for i in ids:
            for s in sets:
                if all(not self.conflict(i, j) for j in s):
                    s.append(i)
                    break
            else:
                sets.append([i])
        return sets

    def conflict(self, a: int, b: int) -> bool:
        return frozenset((a, b)) in self.conflicts

    def light(self, light_id: int) -> Light:
        if light_id not in self.lights:
            raise ControlError(f"no traffic light {light_id} (lights: {sorted(self.lights)})")
        return self.lights[light_id]

    def junction(self, name: str) -> Junction:
        if name not in self.junctions:
            raise ControlError(f"no junction '{name}' (junctions: {sorted(self.junctions)})")
        return self.junctions[name]

    # --- inputs ---------------------------------------------------------------------------------

    def observed(self, light_id: int, state: str, now_s: float) -> None:
        """The simulator's state of a light; the first one is where control starts from."""
        light = self.lights.get(light_id)
        if light is not None and not light.known:
            light.state, light.target, light.since_s, light.known = state, state, now_s, True

    def request(self, light_id: int, state: str, actor: str, now_s: float) -> str:
        """An operator sets a light (its junction goes manual). Returns what will happen."""
        if state not in STATES:
            raise ControlError(f"state must be one of {list(STATES)}, got {state!r}")
        light = self.light(light_id)
        if state == "YELLOW":
            if light.state != "GREEN":
                raise ControlError(
                    f"light {light_id} is {light.state}: YELLOW only follows GREEN (ask for RED)"
                )
            state = "RED"  # yellow is the way to red
        if state == "GREEN":
            for other in self.lights.values():
                if other.id != light_id and self.conflict(light_id, other.id):
                    if other.target == "GREEN":  # one going red is fine: the interlock waits
                        going = f", going {other.target}" if other.target != other.state else ""
                        raise ConflictError(
                            f"light {light_id} -> GREEN refused: conflicting light {other.id} is "
                            f"{other.state}{going} (set light {other.id} to RED first)"
                        )
        junction = self.junctions[light.junction]
        junction.mode = "manual"
        light.target = state
        self.actors[light_id] = actor
        if light.state == "GREEN" and state != "GREEN":
            return f"light {light_id}: YELLOW for {light.program.yellow_s:g} s, then {state}"
        if state == "GREEN" and light.state != "GREEN":
            return f"light {light_id}: GREEN once conflicting lights have been RED {self.min_all_red_s:g} s"
        return f"light {light_id}: {state}"

    def set_mode(self, junction: str, mode: str, max_green_s: float | None = None) -> None:
        if mode not in MODES:
            raise ControlError(f"mode must be one of {list(MODES)}, got {mode!r}")
        j = self.junction(junction)
        if max_green_s is not None:
            if not 1.0 <= max_green_s <= 600.0:
                raise ControlError(f"max_green_s: expected 1..600 [s], got {max_green_s}")
            j.max_green_s = max_green_s
        j.mode = mode
        if mode == "actuated":  # start from the set that is green now, if one is
            for k, s in enumerate(j.sets):
                if any(self.lights[i].state == "GREEN" for i in s):
                    j.active = k
                    break
            j.green_since_s = -1.0

    def set_program(self, light_id: int, program: Program) -> None:
        """A light's new program; refused when it would make conflicting lights green at once."""
        light = self.light(light_id)
        for other in self.lights.values():
            if other.id != light_id and self.conflict(light_id, other.id):
                clash = self._overlap(program, other.program)
                if clash is not None:
                    raise ConflictError(
                        f"program of light {light_id} refused: at t = {clash:.1f} s of the cycle it "
                        f"is non-red together with conflicting light {other.id} (or without "
                        f"{self.min_all_red_s:g} s of all-red between them)"
                    )
        light.program = program

    def _overlap(self, a: Program, b: Program) -> float | None:
        """A time at which the two programs are non-red together or closer than all-red."""
        horizon = max(a.cycle_s, b.cycle_s) * 4
        t, dt = 0.0, 0.05
        while t < horizon:
            sa, sb = a.state_at(t)[0], b.state_at(t)[0]
            if non_red(sa) or non_red(sb):
                other = b if non_red(sa) else a
                for back in (0.0, self.min_all_red_s - 1e-6):
                    if non_red(other.state_at(t - back)[0]):
                        return t
            t += dt
        return None

    # --- the loop -------------------------------------------------------------------------------

    def tick(self, now_s: float, demand: dict[int, bool]) -> list[Change]:
        """Advance to now_s: pick each light's target by its junction's mode, then take each
        light one allowed step towards it. demand: light id -> cars queue on its approach."""
        if self.started_s is None:
            self.started_s = now_s
        for light in self.lights.values():
            if not light.known and now_s - self.started_s >= self.start_grace_s:
                light.known, light.since_s = True, now_s  # nothing seen: assume RED
        for j in self.junctions.values():
            if j.mode == "fixed":
                for i in j.lights:
                    self.lights[i].target = self.lights[i].program.state_at(now_s)[0]
                    self.actors[i] = "program"
            elif j.mode == "actuated":
                self._actuate(j, now_s, demand)
        changes = []
        for light in sorted(self.lights.values(), key=lambda light: light.id):
            if not light.known:
                continue
            new = self._step(light, now_s)
            if new != light.state:
                light.state, light.since_s = new, now_s
                changes.append(Change(light.id, new, self.actors.get(light.id, "server")))
        return changes

    def _step(self, light: Light, now_s: float) -> str:
        """The one state the interlock lets the light take now on its way to its target."""
        want = "RED" if light.target == "YELLOW" else light.target
        if want == light.state:
            return light.state
        if light.state == "GREEN":
            return "YELLOW"
        if light.state == "YELLOW":
            return "RED" if now_s - light.since_s >= light.program.yellow_s - 1e-9 else "YELLOW"
        if want == "GREEN":  # from RED or OFF
            for other in self.lights.values():
                if other.id == light.id or not self.conflict(light.id, other.id):
                    continue
                if non_red(other.state) or now_s - other.since_s < self.min_all_red_s - 1e-9:
                    return light.state
            return "GREEN"
        return want  # RED <-> OFF

    def _actuate(self, j: Junction, now_s: float, demand: dict[int, bool]) -> None:
        def wants(k: int) -> bool:
            return any(demand.get(i, False) for i in j.sets[k])

        cur = j.sets[j.active]
        green = all(self.lights[i].state == "GREEN" for i in cur)
        if green and j.green_since_s < 0:
            j.green_since_s = now_s  # the active set just turned green
        if green:
            held_s = now_s - j.green_since_s
            min_green = max(self.lights[i].program.green_s for i in cur)
            others = [k for k in range(len(j.sets)) if k != j.active and wants(k)]
            queue = wants(j.active)
            if others and held_s >= min_green and (not queue or held_s >= j.max_green_s):
                j.active = min(others, key=lambda k: (k - j.active) % len(j.sets))
                j.green_since_s = -1.0
        for k, s in enumerate(j.sets):
            for i in s:
                self.lights[i].target = "GREEN" if k == j.active else "RED"
                self.actors[i] = "actuated"

    def time_left_s(self, light_id: int, now_s: float) -> float:
        """Time until the light changes [s], <0 when it is not known (manual, actuated green)."""
        light = self.lights[light_id]
        if light.state == "YELLOW":
            return max(0.0, light.program.yellow_s - (now_s - light.since_s))
        j = self.junctions[light.junction]
        if j.mode == "fixed":
            state, left = light.program.state_at(now_s)
            if state == light.state:
                return left
        return -1.0

    @staticmethod
    def program_json(p: Program) -> str:
        return json.dumps(p.to_json())
