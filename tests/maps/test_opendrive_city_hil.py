"""maps.opendrive_city_driver: the smart city's own driver on an imported junction. The crossing
that scenariogeneration writes (autodrive.maps.opendrive.fixtures.crossing) is imported at 1:14;
autodrive-sim runs it in lockstep with the unchanged autodrive-runtime (its EKF fed by the Eye
stand-in), the advisory stand-in (autodrive.hil.city.advisory on the imported sidecar) and
autodrive-city-driver on the generated route r1r1_to_r3r1 (road 1 through the junction to road 3,
past light 1, the light of OpenDRIVE signal 1), all on real LCM, judged on sim time from the
simulator's ground truth and light states:
1. light 3 (signal 6, on road 4, whose approach crosses road 1's) commanded GREEN while light 1
   shows GREEN on its program: the simulator refuses it by the imported conflict and light 3
   stays RED;
2. light 1 commanded RED: the car stops with its front at the imported stop line (at most 3 cm
   past it, at most 25 cm before) and stands there 2 s;
3. light 1 commanded GREEN: the car goes on across the line.
Args: ROOT BUILD PORT."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

from autodrive.hil.city import scoring
from autodrive.maps.opendrive import city_drive, fixtures
from pyhelpers import REPO_ROOT

TOOL = REPO_ROOT / "tools" / "map"
ROUTE = "r1r1_to_r3r1"  # road 1 through the junction to road 3, past light 1
LIGHT, CROSSING_LIGHT = 1, 3  # signal 1 on road 1; signal 6 on road 4 (crossing road 1)
RED, GREEN = 1, 3
START_BEFORE_LINE_M = 0.8  # the car starts this far before light 1's stop line [m]
SIM_LIMIT_S = 60.0


def test_city_driver_stops_at_an_imported_red_light(
    build_dir: Path, lcm_url: str, tmp_path: Path
) -> None:
    maps = tmp_path / "maps"
    xodr = fixtures.crossing(tmp_path / "crossing.xodr")
    run = subprocess.run([str(TOOL), "import", str(xodr), "--scale", "1:14", "--name", "crossing",
                          "--out", str(maps)], capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 0, run.stderr
    sidecar = maps / "crossing.json"
    doc = json.loads(sidecar.read_text())
    assert [LIGHT, CROSSING_LIGHT] in doc["light_conflicts"], doc["light_conflicts"]
    line = scoring.MapFacts.load(sidecar).stop_for_light(LIGHT)
    lane = next(t for t in doc["traffic_lights"] if t["id"] == LIGHT)["lane"]
    start = city_drive.start_before(doc, lane, (line.x_m, line.y_m), START_BEFORE_LINE_M)
    out = tmp_path / "out"
    stack = city_drive.CityStack(sidecar, ROUTE, build_dir, lcm_url, out,
                                 lambda m: print(f"[xodr-city] {m}", flush=True), SIM_LIMIT_S)  # fmt: skip
    tr = stack.truth

    def past() -> float:
        return scoring.front_past_m(tr["x"], tr["y"], tr["yaw"], line)

    try:
        stack.start(start)
        # 1. the crossing approach's light may not turn green while light 1 is green
        stack.wait_for("light 1 GREEN on its program", lambda: stack.lights.get(LIGHT) == GREEN)
        refusal = f"light {CROSSING_LIGHT} -> GREEN refused: conflicting light {LIGHT} is GREEN"
        sent = [-1.0]

        def refused() -> bool:  # sent again each 0.5 s of sim time until the sim answers
            assert stack.lights.get(CROSSING_LIGHT) != GREEN, "a crossing green was shown"
            if refusal in (out / "sim.log").read_text():
                return True
            if sent[0] < 0 or tr["t"] - sent[0] > 0.5:
                stack.command(CROSSING_LIGHT, GREEN)
                sent[0] = tr["t"]
            return False

        stack.wait_for("the crossing green refused", refused, 5.0)
        t_cmd = tr["t"]
        stack.wait_for("1 s on", lambda: tr["t"] > t_cmd + 1.0)
        assert stack.lights.get(CROSSING_LIGHT) == RED, stack.lights  # light 1 may be yellow now
        print(f"1. light {CROSSING_LIGHT} GREEN refused while light {LIGHT} is GREEN")
        # 2. light 1 RED: the city driver stops the car at the imported stop line
        stack.hold(LIGHT, RED, "light 1 RED")
        stack.start_driver()
        stack.wait_for("driving", lambda: tr["v"] > 0.05)
        stack.wait_for("stood 2 s at light 1's stop line", stack.stood_at(line, 2.0))
        over = past()
        print(f"2. red: stood {-over * 100:.1f} cm before the stop line at t={tr['t']:.1f} s")
        assert stack.lights[LIGHT] == RED and over <= 0.03, (over, stack.lights)
        assert "red light 1" in (out / "driver.log").read_text()
        # 3. light 1 GREEN: on across the line
        stack.hold(LIGHT, GREEN, "light 1 GREEN")
        stack.wait_for("across the line on green", lambda: past() > 0.3)
        print(f"3. green: crossed the line at t={tr['t']:.1f} s of sim time")
        rep = stack.scorer.report()
        assert rep["red_light_violations"] == 0 and rep["collisions"] == 0, rep
    finally:
        stack.stop()
        for f in ("driver.log", "runtime.log", "sim.log"):
            p = out / f
            if p.exists():
                print(f"---- {f} (tail)\n" + "\n".join(p.read_text().splitlines()[-15:]))
