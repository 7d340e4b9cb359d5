"""A first OpenSCENARIO subset (read by scenariogeneration's reader) on an imported map: the
Init's TeleportAction (WorldPosition) and AbsoluteSpeedAction of each entity, and events whose
actions are TrafficSignalStateAction, started by a SimulationTimeCondition or a
ReachPositionCondition (WorldPosition, tolerance). Anything else is refused by name. Positions,
tolerances and speeds are the file's (full scale): the map's imported_from takes them to ours.
run() plays a plan in autodrive-sim: the entities' start poses (--start, car k = the k-th
entity) and the light changes as signed TRAFFIC_LIGHT_COMMANDs (the SCM's key), each when its
condition holds on the simulator's clock (its TRAFFIC_LIGHT_STATE and GROUND_TRUTH times)."""

from __future__ import annotations

import math
import select
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from autodrive.maps.model import MapDescriptionError

STATES = {"off": 0, "red": 1, "yellow": 2, "green": 3}  # the kit's light states


class ScenarioError(MapDescriptionError):
    """An OpenSCENARIO file outside the subset, or that does not fit the map; names the file,
    the element and what is wrong."""


@dataclass(frozen=True)
class LightChange:
    """Set lights to state when the sim time reaches at_s, or when entity comes within
    tolerance_m of position_m (ours) — exactly one of the two."""

    event: str
    light_ids: list[int]
    state: int
    at_s: float | None = None
    entity: str | None = None
    position_m: tuple[float, float] | None = None
    tolerance_m: float = 0.0


@dataclass
class Plan:
    entities: list[str]
    starts: dict[str, tuple[float, float, float]]  # x [m], y [m], yaw [rad], ours
    speeds_m_s: dict[str, float]  # ours (scaled)
    changes: list[LightChange] = field(default_factory=list)


def _cls(obj: Any) -> str:
    return type(obj).__name__


class _Reader:
    def __init__(self, path: Path, imported: dict[str, Any]) -> None:
        self.path = path
        self.scale = float(imported["scale"])
        self.offset = imported["offset_m"]
        self.lights_of: dict[str, list[int]] = imported.get("signal_lights", {})

    def fail(self, where: str, what: str) -> ScenarioError:
        return ScenarioError(f"{self.path}: {where}: {what}")

    def xy(self, pos: Any, where: str) -> tuple[float, float, float]:
        if _cls(pos) != "WorldPosition":
            raise self.fail(where, f"unsupported position {_cls(pos)} (supported: WorldPosition)")
        x, y = float(pos.x), float(pos.y)
        h = float(pos.h or 0.0)
        return self.scale * x + self.offset[0], self.scale * y + self.offset[1], h

    def plan(self, sc: Any) -> Plan:
        init = sc.storyboard.init
        if init.global_actions or init.user_defined_actions:
            raise self.fail("Init", "only private actions (TeleportAction, AbsoluteSpeedAction)")
        names = [o.name for o in sc.entities.scenario_objects]
        p = Plan(names, {}, {})
        for ent, actions in init.initactions.items():
            for i, a in enumerate(actions):
                where = f"Init.Private[{ent}].action[{i}]"
                if _cls(a) == "TeleportAction":
                    p.starts[ent] = self.xy(a.position, where)
                elif _cls(a) == "AbsoluteSpeedAction":
                    p.speeds_m_s[ent] = float(a.speed) * self.scale
                else:
                    raise self.fail(where, f"unsupported action {_cls(a)} (supported: "
                                    "TeleportAction, AbsoluteSpeedAction)")  # fmt: skip
        for ent in names:
            if ent not in p.starts:
                raise self.fail(f"Init.Private[{ent}]", "no TeleportAction: where does it start?")
        for si, story in enumerate(sc.storyboard.stories):
            for ai, act in enumerate(story.acts):
                for gi, group in enumerate(act.maneuvergroup):
                    for mi, man in enumerate(group.maneuvers):
                        for ei, ev in enumerate(man.events):
                            where = f"Story[{si}].Act[{ai}].ManeuverGroup[{gi}].Maneuver[{mi}].Event[{ei}] '{ev.name}'"
                            p.changes += self.event(ev, where)
        return p

    def event(self, ev: Any, where: str) -> list[LightChange]:
        trig = self.trigger(ev.trigger, where)
        out = []
        for k, wrapped in enumerate(ev.action):
            a = wrapped.action
            aw = f"{where}.Action[{k}]"
            if _cls(a) != "TrafficSignalStateAction":
                raise self.fail(aw, f"unsupported action {_cls(a)} (supported in events: "
                                "TrafficSignalStateAction)")  # fmt: skip
            state = STATES.get(str(a.state).lower())
            if state is None:
                raise self.fail(f"{aw}.state", f"unknown state {a.state!r} (known: {list(STATES)})")
            ids = self.lights_of.get(str(a.name))
            if not ids:
                raise self.fail(f"{aw}.name", f"no light for signal '{a.name}' on this map "
                                f"(signals with lights: {sorted(self.lights_of)})")  # fmt: skip
            out.append(LightChange(ev.name, ids, state, **trig))
        return out

    def trigger(self, trig: Any, where: str) -> dict[str, Any]:
        groups = trig.conditiongroups if trig is not None else []
        if len(groups) != 1 or len(groups[0].conditions) != 1:
            raise self.fail(f"{where}.StartTrigger", "give exactly one condition")
        c = groups[0].conditions[0]
        cw = f"{where}.StartTrigger.Condition '{c.name}'"
        if _cls(c) == "ValueTrigger" and _cls(c.valuecondition) == "SimulationTimeCondition":
            return {"at_s": float(c.valuecondition.value) + float(c.delay)}
        if _cls(c) == "EntityTrigger" and _cls(c.entitycondition) == "ReachPositionCondition":
            ents = c.triggerentity.entity if hasattr(c, "triggerentity") else []
            names = [e.entity for e in ents]
            if len(names) != 1:
                raise self.fail(cw, "give one triggering entity")
            x, y, _ = self.xy(c.entitycondition.position, cw)
            tol = float(c.entitycondition.tolerance) * self.scale
            return {"entity": names[0], "position_m": (x, y), "tolerance_m": tol}
        inner = _cls(getattr(c, "valuecondition", None) or getattr(c, "entitycondition", None))
        raise self.fail(cw, f"unsupported condition {inner} (supported: SimulationTimeCondition, "
                        "ReachPositionCondition)")  # fmt: skip


def read(path: Path, imported: dict[str, Any]) -> Plan:
    """The plan of an .xosc on a map imported with imported_from (the sidecar's record)."""
    from scenariogeneration import xosc  # type: ignore[import-untyped]

    if not path.is_file():
        raise ScenarioError(f"{path}: no such file")
    try:
        sc = xosc.ParseOpenScenario(str(path))
    except Exception as err:  # the reader raises many kinds; all mean "not a scenario we read"
        raise ScenarioError(
            f"{path}: not a readable OpenSCENARIO file ({_cls(err)}: {err})"
        ) from err
    return _Reader(path, imported).plan(sc)


@dataclass
class Played:
    """What the simulator showed: light id -> [(sim s, state)] as it changed, and each
    entity's first pose (ground truth) [m, m, rad]."""

    light_states: dict[int, list[tuple[float, int]]]
    first_poses: dict[str, tuple[float, float, float]]
    fired: list[tuple[float, str]]  # (sim s, event) as commanded


def run(plan: Plan, map_xml: Path, build: Path, lcm_url: str, run_dir: Path, duration_s: float,
        log: Callable[[str], None]) -> Played:  # fmt: skip
    """Plays the plan in autodrive-sim (real time, its own clock) for duration_s of sim time."""
    from autodrive.core import lcmtypes, v2x_auth, v2x_ca
    from autodrive.core.channels import channel, vehicle_name
    from autodrive.core.proc import ProcessGroup

    types = lcmtypes.load(build)
    cars = [vehicle_name(i + 1) for i in range(len(plan.entities))]
    v2x_ca.ensure_run_keys(cars, log)
    signer, clock = v2x_auth.MessageSigner(v2x_ca.load_identity("SCM")), v2x_auth.BusClock()
    lc = lcmtypes.bus(lcm_url)
    played = Played({}, {}, [])
    pose: dict[str, tuple[float, float]] = {}
    sim_s = [0.0]

    def on_light(_ch: str, data: bytes) -> None:
        m = types.traffic_light_state_t.decode(data)
        clock.heard(m.utime)
        sim_s[0] = max(sim_s[0], m.utime * 1e-6)
        seen = played.light_states.setdefault(m.light_id, [])
        if not seen or seen[-1][1] != m.state:
            seen.append((m.utime * 1e-6, m.state))

    lc.subscribe(channel("TRAFFIC_LIGHT_STATE"), on_light)
    for ent, car in zip(plan.entities, cars):

        def on_truth(_ch: str, data: bytes, ent: str = ent) -> None:
            m = types.ground_truth_t.decode(data)
            sim_s[0] = max(sim_s[0], m.utime * 1e-6)
            pose[ent] = (m.position_m[0], m.position_m[1])
            played.first_poses.setdefault(ent, (m.position_m[0], m.position_m[1], m.yaw_rad))

        lc.subscribe(channel("GROUND_TRUTH", car), on_truth)
    sim = [str(build / "bin" / "autodrive-sim"), "--map", str(map_xml), "--cars", str(len(cars))]
    for ent in plan.entities:
        x, y, h = plan.starts[ent]
        sim += ["--start", f"{x:.5f},{y:.5f},{math.degrees(h):.4f}"]
    sim += ["--run-dir", str(run_dir), "--lcm-url", lcm_url, "--duration", f"{duration_s + 2:g}"]
    procs = ProcessGroup(log)
    pending = list(plan.changes)
    try:
        procs.start("autodrive-sim", sim, run_dir / "sim.log")
        while sim_s[0] < duration_s:
            procs.check()
            if select.select([lc.fileno()], [], [], 0.05)[0]:
                lc.handle()
            for ch in [c for c in pending if _due(c, sim_s[0], pose)]:
                pending.remove(ch)
                played.fired.append((sim_s[0], ch.event))
                for lid in ch.light_ids:
                    cmd = types.traffic_light_command_t()
                    cmd.utime, cmd.light_id, cmd.state, cmd.duration_s = (
                        clock.now_us(),
                        lid,
                        ch.state,
                        0.0,
                    )
                    signer.sign(channel("TRAFFIC_LIGHT_COMMAND"), cmd, clock.now_us())
                    lc.publish(channel("TRAFFIC_LIGHT_COMMAND"), cmd.encode())
                log(f"t={sim_s[0]:.2f} s: event '{ch.event}': lights {ch.light_ids} -> {ch.state}")
    finally:
        procs.stop_all()
    return played


def _due(c: LightChange, now_s: float, pose: dict[str, tuple[float, float]]) -> bool:
    if c.at_s is not None:
        return now_s >= c.at_s
    assert c.entity is not None and c.position_m is not None
    p = pose.get(c.entity)
    return p is not None and math.dist(p, c.position_m) <= c.tolerance_m
