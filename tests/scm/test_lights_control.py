"""Unit tests of the SCM's light control rules (autodrive.scm.lights), on Tiny Town's
four lights and their conflicts from the map description, with time passed in: GREEN -> RED
always passes YELLOW for the light's yellow time; a GREEN waits for the all-red time after a
conflicting light turned RED; a GREEN against a conflicting green is refused naming it; no
tick ever leaves two conflicting lights non-red; fixed-time programs follow their phases and a
conflicting program is refused; actuated control holds green while cars queue, up to
max_green_s, and gives way at min green when nobody queues; bad programs are refused naming
the field."""

from __future__ import annotations

import itertools

from autodrive import maps
from autodrive.scm.lights import (
    ConflictError,
    ControlError,
    Controller,
    Light,
    Program,
    non_red,
)


def test_light_control_rules() -> None:
    m = maps.load("tiny_town")
    CONFLICTS = m.light_conflicts()
    ALL_RED_S = m.kit.traffic_light.min_all_red_s
    failures = 0

    def check(cond: bool, what: str) -> None:
        nonlocal failures
        print(("ok: " if cond else "FAIL: ") + what, flush=True)
        failures += not cond

    def make(mode: str = "manual") -> Controller:
        lights = []
        for t in m.lights():
            p = t.program
            lights.append(
                Light(t.id, "x", Program.from_map(p.cycle_s, p.offset_s, p.green_s, p.yellow_s))
            )
        c = Controller(lights, CONFLICTS, ALL_RED_S, start_grace_s=0.0)
        for light in c.lights.values():
            c.observed(light.id, "RED", -10.0)  # red for 10 s already
        c.junctions["x"].mode = mode
        return c

    def safe(c: Controller) -> bool:
        for a, b in itertools.combinations(c.lights.values(), 2):
            if c.conflict(a.id, b.id) and non_red(a.state) and non_red(b.state):
                return False
        return True

    def run(
        c: Controller, t0: float, t1: float, demand: dict[int, bool] | None = None, dt: float = 0.05
    ) -> list[tuple[float, int, str]]:
        log = []
        t = t0
        while t < t1 - 1e-9:
            for ch in c.tick(t, demand or {}):
                log.append((round(t, 3), ch.light_id, ch.state))
            assert safe(
                c
            ), f"conflicting lights non-red at t = {t:.2f}: {[(l.id, l.state) for l in c.lights.values()]}"
            t += dt
        return log

    check(
        sorted(CONFLICTS) == [(1, 2), (1, 4), (2, 3), (3, 4)],
        f"conflicts from the map: {CONFLICTS}",
    )

    # manual: GREEN, then RED through YELLOW for the yellow time
    c = make()
    c.request(1, "GREEN", "op", 0.0)
    log = run(c, 0.0, 1.0)
    check(log[0] == (0.0, 1, "GREEN"), f"light 1 GREEN at once (all red long enough): {log}")
    c.request(1, "RED", "op", 1.0)
    log = run(c, 1.0, 5.0)
    yellow = [e for e in log if e[1] == 1]
    check(yellow[0][2] == "YELLOW" and yellow[1][2] == "RED", f"GREEN -> YELLOW -> RED: {yellow}")
    check(abs(yellow[1][0] - yellow[0][0] - 2.0) < 0.051, f"yellow held 2 s: {yellow}")

    # a GREEN against a conflicting green is refused, naming the light; a yellow-to-red one waits
    c = make()
    c.request(1, "GREEN", "op", 0.0)
    run(c, 0.0, 0.5)
    try:
        c.request(2, "GREEN", "op", 0.5)
        check(False, "light 2 GREEN while light 1 GREEN was accepted")
    except ConflictError as err:
        check("conflicting light 1" in str(err), f"refused: {err}")
    c.request(3, "GREEN", "op", 0.5)  # opposite approach: no conflict
    run(c, 0.5, 1.0)
    check(c.lights[3].state == "GREEN", "light 3 (opposite, no conflict) GREEN with light 1")
    c.request(1, "RED", "op", 1.0)
    c.request(3, "RED", "op", 1.0)
    c.request(2, "GREEN", "op", 1.0)  # accepted: 1 and 3 are on their way to red
    log = run(c, 1.0, 6.0)
    red_at = max(t for t, i, s in log if s == "RED")
    green2 = [t for t, i, s in log if i == 2 and s == "GREEN"]
    check(
        bool(green2) and green2[0] - red_at >= ALL_RED_S - 1e-6,
        f"light 2 GREEN {green2[0] - red_at if green2 else -1:.2f} s after the last conflicting RED (all-red {ALL_RED_S} s)",
    )
    try:
        c.request(4, "YELLOW", "op", 6.0)
        check(False, "YELLOW from RED accepted")
    except ControlError as err:
        check("YELLOW only follows GREEN" in str(err), f"YELLOW from RED refused: {err}")

    # fixed time: the map's programs, yellow and all-red kept, never two conflicting greens
    c = make("fixed")
    log = run(c, 0.0, 60.0)
    g1 = [t for t, i, s in log if i == 1 and s == "GREEN"]
    y1 = [t for t, i, s in log if i == 1 and s == "YELLOW"]

    def near(got: list[float], want: list[float]) -> bool:  # within one 50 ms tick
        return len(got) >= len(want) and all(abs(a - b) <= 0.051 for a, b in zip(got, want))

    check(
        near(g1, [0.0, 20.0, 40.0]) and near(y1, [6.0, 26.0, 46.0]),
        f"light 1 on its program: green {g1} yellow {y1}",
    )
    g2 = [t for t, i, s in log if i == 2 and s == "GREEN"]
    check(near(g2, [10.0, 30.0, 50.0]), f"light 2 on its program: {g2}")
    # an operator's program that would overlap a conflicting light is refused
    bad = Program.from_json(
        {
            "offset_s": 4.0,
            "phases": [
                {"state": "GREEN", "duration_s": 6.0},
                {"state": "YELLOW", "duration_s": 2.0},
                {"state": "RED", "duration_s": 12.0},
            ],
        }
    )
    try:
        c.set_program(2, bad)
        check(False, "overlapping program accepted")
    except ConflictError as err:
        check("conflicting light 1" in str(err), f"overlapping program refused: {err}")
    good = Program.from_json(
        {
            "offset_s": 10.0,
            "phases": [
                {"state": "GREEN", "duration_s": 5.0},
                {"state": "YELLOW", "duration_s": 2.0},
                {"state": "RED", "duration_s": 13.0},
            ],
        }
    )
    c.set_program(2, good)
    check(c.lights[2].program == good, "a compatible program is taken")
    for doc, field in (
        ({"phases": []}, "phases"),
        (
            {"phases": [{"state": "GREEN", "duration_s": 5}, {"state": "RED", "duration_s": 5}]},
            "followed by YELLOW",
        ),
        ({"phases": [{"state": "BLUE", "duration_s": 5}]}, "state"),
        ({"phases": [{"state": "RED", "duration_s": -1}]}, "duration_s"),
        ({"offset": 1, "phases": [{"state": "RED", "duration_s": 5}]}, "unknown field"),
    ):
        try:
            Program.from_json(doc)
            check(False, f"bad program accepted: {doc}")
        except ControlError as err:
            check(field in str(err), f"bad program refused: {err}")

    # actuated: sets {1, 3} and {2, 4}; a queue on light 1 holds green past min green up to max
    c = make("actuated")
    c.junctions["x"].max_green_s = 12.0
    c.set_mode("x", "actuated")
    run(c, 0.0, 2.0)
    check(
        c.lights[1].state == "GREEN" and c.lights[3].state == "GREEN",
        "actuated: set {1, 3} green first",
    )
    log = run(c, 2.0, 30.0, {1: True, 2: True})
    y1 = [t for t, i, s in log if i == 1 and s == "YELLOW"]
    check(
        bool(y1) and abs(y1[0] - 12.0) < 0.11,
        f"queue on light 1: green held to max_green 12 s (yellow at {y1[:1]})",
    )
    c = make("actuated")
    c.set_mode("x", "actuated")
    run(c, 0.0, 2.0)
    log = run(c, 2.0, 30.0, {2: True})
    y1 = [t for t, i, s in log if i == 1 and s == "YELLOW"]
    g2 = [t for t, i, s in log if i == 2 and s == "GREEN"]
    check(
        bool(y1) and abs(y1[0] - 6.0) < 0.11,
        f"no queue on light 1: yellow at min green 6 s ({y1[:1]})",
    )
    check(
        bool(g2) and abs(g2[0] - (y1[0] + 2.0 + ALL_RED_S)) < 0.11,
        f"light 2 green after yellow + all-red ({g2[:1]})",
    )
    log = run(c, 30.0, 60.0, {})
    check(not log, "no demand anywhere: the green rests where it is")

    assert failures == 0, f"{failures} FAILED"
    print("OK")
